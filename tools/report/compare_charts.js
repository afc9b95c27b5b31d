// Session comparison charts: reads window.RMS_COMPARE (tools/rms_report contract), draws into #rms-charts
// with Chart.js 3.9, then sets body[data-charts-rendered] to the number of charts made.
(function () {
  'use strict';
  const C = window.RMS_COMPARE || {};
  const PALETTE = ['#1f77b4', '#ff7f0e', '#2ca02c', '#d62728', '#9467bd', '#8c564b', '#e377c2', '#7f7f7f',
    '#bcbd22', '#17becf'];
  const made = [];
  const errors = [];

  const arr = (v) => (Array.isArray(v) ? v : []);
  const num = (v) => typeof v === 'number' && isFinite(v);
  const sessions = arr(C.sessions).map((s) => (s && typeof s === 'object' ? s : {}));

  // Task time of the session's best attempt (the contract's "best"); null = not docked. Without a
  // "best" field at all, the fastest attempt that has a task time.
  function taskTime(s) {
    if (s.best && typeof s.best === 'object') return num(s.best.task_time_s) ? s.best.task_time_s : null;
    if (s.best !== undefined) return null;
    const ts = arr(s.attempts).map((a) => a && a.task_time_s).filter(num);
    return ts.length ? Math.min(...ts) : null;
  }

  // Collisions over all the session's attempts (the best's if attempts are not given).
  function collisions(s) {
    const cs = arr(s.attempts).map((a) => a && a.collisions).filter(num);
    if (cs.length) return cs.reduce((a, b) => a + b, 0);
    return s.best && num(s.best.collisions) ? s.best.collisions : null;
  }

  const nameOf = (i) => String(sessions[i].name || 'session ' + (i + 1));
  // Tick label: the name, with a second line when the session never docked.
  const labelOf = (i) => (taskTime(sessions[i]) === null ? [nameOf(i), '(not docked)'] : nameOf(i));

  // {subject: [session indices]} for the learning curves: the contract's map, else by each session's subject.
  function subjects() {
    const out = {};
    const given = C.subjects && typeof C.subjects === 'object' ? C.subjects : null;
    Object.keys(given || {}).forEach((k) => {
      const idx = arr(given[k]).filter((i) => Number.isInteger(i) && i >= 0 && i < sessions.length);
      if (idx.length) out[k] = idx;
    });
    if (given) return out;
    sessions.forEach((s, i) => {
      const k = String(s.subject || '(no subject)');
      (out[k] = out[k] || []).push(i);
    });
    return out;
  }

  // The overall chart's groups: the subjects, then the sessions in none (re-simulations apart).
  function groups(subs) {
    const out = Object.assign({}, subs);
    const covered = new Set([].concat(...Object.values(subs)));
    sessions.forEach((s, i) => {
      if (covered.has(i)) return;
      const k = s.kind === 're-simulation' ? 're-simulations' : '(no subject)';
      (out[k] = out[k] || []).push(i);
    });
    return out;
  }

  const { el } = window.RmsCharts;  // chart_page.js
  // A titled section's canvas, of the given height.
  const section = (title, height) => window.RmsCharts.section(title, height).canvas;

  const note = (text) => el('p', { className: 'rms-chart-note', textContent: text }, document.getElementById('rms-charts'));

  // Tooltip footer lines describing session i.
  function about(i) {
    const s = sessions[i];
    const b = s.best && typeof s.best === 'object' ? s.best : {};
    const lines = [];
    if (s.subject) lines.push('subject: ' + s.subject);
    if (s.note) lines.push('note: ' + s.note);
    if (s.started_utc) lines.push('started: ' + s.started_utc + (s.kind ? ' (' + s.kind + ')' : ''));
    lines.push('attempts: ' + arr(s.attempts).length + (b.outcome ? ', outcome: ' + b.outcome : ''));
    if (num(b.dock_distance_ft)) lines.push('dock miss: ' + b.dock_distance_ft.toFixed(3) + ' ft');
    if (num(b.dock_angle_deg)) lines.push('dock angle: ' + b.dock_angle_deg.toFixed(2) + ' deg');
    if (taskTime(s) === null) lines.push('not docked');
    return lines;
  }

  function baseOptions(title) {
    return {
      animation: false, responsive: true, maintainAspectRatio: false,
      interaction: { mode: 'index', intersect: false },
      scales: {
        x: { title: { display: true, text: 'session, in start order' } },
        y: { beginAtZero: true, grace: '8%', title: { display: true, text: 'task time, s' } },
      },
      plugins: {
        title: { display: true, text: title },
        legend: { labels: { boxWidth: 14 } },
        tooltip: { callbacks: {} },
      },
    };
  }

  // Learning curve of one subject: best task time (line) and collisions (bars, right axis).
  function learningCurve(subject, idx, colour) {
    const times = idx.map((i) => taskTime(sessions[i]));
    const cols = idx.map((i) => collisions(sessions[i]));
    const o = baseOptions(subject + ': task time of the best attempt per session (missing point = not docked)');
    o.scales.y1 = { position: 'right', beginAtZero: true, grace: '8%', display: 'auto', grid: { drawOnChartArea: false },
      ticks: { precision: 0 }, title: { display: true, text: 'collisions' } };
    o.plugins.tooltip.callbacks.footer = (items) => (items.length ? about(idx[items[0].dataIndex]) : []);
    o.plugins.tooltip.callbacks.label = (c) => c.dataset.label.split(' (')[0] + ': ' +
      (c.raw === null ? 'none (not docked)' : c.raw);
    const ds = [{
      type: 'line', label: 'task time, s (gap = not docked)', data: times, yAxisID: 'y', spanGaps: false,
      borderColor: colour, backgroundColor: colour, pointRadius: 5, borderWidth: 2, order: 0,
    }];
    if (cols.some(num)) {
      ds.push({ type: 'bar', label: 'collisions in the session', data: cols, yAxisID: 'y1',
        backgroundColor: 'rgba(214,39,40,0.35)', borderColor: '#d62728', borderWidth: 1, order: 1,
        maxBarThickness: 40 });
    }
    made.push(new Chart(section('Learning curve: ' + subject, 300), {
      type: 'bar', data: { labels: idx.map(labelOf), datasets: ds }, options: o,
    }));
  }

  // Every session's best task time, one bar colour per subject; no bar = not docked.
  function overall(subs) {
    const keys = Object.keys(subs);
    const o = baseOptions('Task time per session, coloured by subject (no bar = not docked)');
    o.interaction = { mode: 'nearest', intersect: true };
    o.plugins.tooltip.callbacks.footer = (items) => (items.length ? about(items[0].dataIndex) : []);
    o.plugins.tooltip.callbacks.label = (c) => c.dataset.label + ': ' + c.raw + ' s';
    const ds = keys.map((k, n) => {
      const mine = new Set(subs[k]);
      return {
        label: k, data: sessions.map((s, i) => (mine.has(i) ? taskTime(s) : null)), skipNull: true,
        backgroundColor: PALETTE[n % PALETTE.length], borderColor: PALETTE[n % PALETTE.length],
        maxBarThickness: 40,
      };
    });
    made.push(new Chart(section('Task time of all sessions', 340), {
      type: 'bar', data: { labels: sessions.map((s, i) => labelOf(i)), datasets: ds }, options: o,
    }));
  }

  function main() {
    if (!document.getElementById('rms-charts')) el('div', { id: 'rms-charts' }, document.body);
    const draw = (f) => {
      try { f(); } catch (e) { errors.push(String(e)); console.error('rms compare chart:', e); }
    };
    if (typeof Chart === 'undefined') errors.push('Chart.js is not loaded');
    else if (!sessions.length) note('no sessions to compare');
    else {
      const subs = subjects();
      Object.keys(subs).forEach((k, n) => draw(() => learningCurve(k, subs[k], PALETTE[n % PALETTE.length])));
      draw(() => overall(groups(subs)));
    }
    document.body.dataset.chartsRendered = String(made.length);
    if (errors.length) document.body.dataset.chartsError = errors.join('; ');
  }

  if (document.readyState === 'loading') document.addEventListener('DOMContentLoaded', main);
  else main();
})();

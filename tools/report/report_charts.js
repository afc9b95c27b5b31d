// Session report charts: reads window.RMS_REPORT (tools/rms_report contract), draws into #rms-charts
// with Chart.js 3.9, then sets body[data-charts-rendered] to the number of charts made.
(function () {
  'use strict';
  const R = window.RMS_REPORT || {};
  const S = R.series || {};
  const G = R.geometry || {};
  const MODE_COLOR = { 0: '#888888', 1: '#1f77b4', 2: '#ff7f0e', 3: '#2ca02c' };
  const MODE_NAME = { 0: 'mode unknown', 1: 'Mode 1 acquisition', 2: 'Mode 2 extraction',
    3: 'Mode 3 manoeuvring and docking' };
  const PALETTE = ['#1f77b4', '#ff7f0e', '#2ca02c', '#d62728', '#9467bd', '#8c564b', '#e377c2', '#7f7f7f'];
  const KINDS = ['mode', 'collision', 'hold', 'reset', 'restore', 'freeze', 'restart'];
  const KIND_COLOR = { mode: '#1f77b4', collision: '#d62728', hold: '#9467bd', reset: '#8c564b',
    restore: '#17becf', freeze: '#7f7f7f', restart: '#e377c2' };
  const MAX_PATH = 1500;   // points per path view
  const MAX_TIME = 2000;   // points per time series
  const made = [];
  const errors = [];

  const arr = (v) => (Array.isArray(v) ? v : []);
  const num = (v) => typeof v === 'number' && isFinite(v);
  const lo = (v) => v.reduce((a, b) => (b < a ? b : a), Infinity);
  const hi = (v) => v.reduce((a, b) => (b > a ? b : a), -Infinity);
  const titled = (text) => ({ display: true, text });
  const T = arr(S.t_s);
  const M = arr(S.mode);
  const A = arr(S.attempt);
  const modeAt = (i) => ([1, 2, 3].indexOf(M[i]) >= 0 ? M[i] : 0);
  const keyAt = (i) => modeAt(i) + '/' + A[i];

  // Evenly picked indices of 0..n-1, keeping both samples around every mode or attempt change.
  function pick(n, max) {
    const step = Math.max(1, Math.ceil(n / max));
    const out = [];
    const keep = (i) => i % step === 0 || i === n - 1 || keyAt(i) !== keyAt(i - 1) || keyAt(i) !== keyAt(i + 1);
    for (let i = 0; i < n; i++) if (keep(i)) out.push(i);
    return out;
  }

  // Points pt(i) of mode m (or any mode if m is null) over idx, with a null break wherever the
  // run of mode m / one attempt is interrupted or a value is missing: no line crosses a gap.
  function runs(idx, m, pt) {
    const out = [];
    let last = -2;
    idx.forEach((i, j) => {
      if (m !== null && modeAt(i) !== m) return;
      const p = pt(i);
      if (!p || !num(p.x) || !num(p.y)) return;
      if (out.length && (last !== j - 1 || keyAt(idx[last]) !== keyAt(i))) out.push({ x: p.x, y: null });
      out.push(p);
      last = j;
    });
    return out;
  }

  function modesPresent(n) {
    const seen = new Set(Array.from({ length: n }, (_, i) => modeAt(i)));
    return [0, 1, 2, 3].filter((m) => seen.has(m));
  }

  const { el, section } = window.RmsCharts;  // chart_page.js

  function note(sec, text) {
    sec.box.remove();
    el('p', { className: 'rms-chart-note', textContent: text }, sec.div);
  }

  // Session time range, including the ends of timed events.
  function timeRange() {
    const ts = T.filter(num);
    arr(R.events).forEach((e) => e && num(e.t_s) && ts.push(e.t_s + (num(e.duration_s) ? e.duration_s : 0)));
    if (!ts.length) return { min: 0, max: 1 };
    return { min: lo(ts), max: hi(ts) > lo(ts) ? hi(ts) : lo(ts) + 1 };
  }

  // Shades every other attempt and draws a dashed line and label at each attempt start.
  const attemptPlugin = {
    id: 'rmsAttempts',
    beforeDatasetsDraw(c) {
      const list = arr(R.attempts).filter((a) => a && num(a.start_s));
      const { ctx, chartArea: a, scales: { x } } = c;
      if (list.length < 2 || !x || !a) return;
      ctx.save();
      ctx.beginPath();
      ctx.rect(a.left, a.top, a.right - a.left, a.bottom - a.top);
      ctx.clip();
      list.forEach((at, k) => {
        const x0 = x.getPixelForValue(at.start_s);
        const x1 = x.getPixelForValue(num(at.end_s) ? at.end_s : x.max);
        if (k % 2) {
          ctx.fillStyle = 'rgba(0,0,0,0.06)';
          ctx.fillRect(x0, a.top, x1 - x0, a.bottom - a.top);
        }
        Object.assign(ctx, { strokeStyle: '#666', fillStyle: '#444', font: '11px sans-serif' });
        ctx.setLineDash([4, 3]);
        ctx.beginPath();
        ctx.moveTo(x0, a.top);
        ctx.lineTo(x0, a.bottom);
        ctx.stroke();
        ctx.fillText('attempt ' + (at.index != null ? at.index : k + 1), x0 + 4, a.top + 12);
      });
      ctx.restore();
    },
  };

  function timeOptions(ytitle) {
    const r = timeRange();
    return {
      animation: false, parsing: false, responsive: true, maintainAspectRatio: false,
      interaction: { mode: 'nearest', axis: 'x', intersect: false },
      elements: { point: { radius: T.length > 1 ? 0 : 3 }, line: { borderWidth: 1.5 } },
      scales: {
        x: { type: 'linear', min: r.min, max: r.max, afterBuildTicks: niceTicks, title: titled('session time, s') },
        y: { title: titled(ytitle) },
      },
      plugins: {
        legend: { labels: { boxWidth: 14 } },
        tooltip: { callbacks: { title: (it) => (it.length ? 't = ' + it[0].parsed.x.toFixed(2) + ' s' : '') } },
      },
    };
  }

  // A chart against session time, with the attempts marked.
  function timeChart(canvas, config) {
    config.plugins = [attemptPlugin];
    made.push(new Chart(canvas, config));
  }

  function rect(box, a, b) {
    const [u, v] = [box && box[a], box && box[b]];
    if (!Array.isArray(u) || !Array.isArray(v) || ![u[0], u[1], v[0], v[1]].every(num)) return null;
    return [{ x: u[0], y: v[0] }, { x: u[1], y: v[0] }, { x: u[1], y: v[1] }, { x: u[0], y: v[1] }, { x: u[0], y: v[0] }];
  }

  // Widens the axis ranges of c so that one ft is the same number of pixels on both axes.
  function equalize(c, e) {
    for (let k = 0; k < 4; k++) {
      const a = c.chartArea;
      const [w, h] = [a.right - a.left, a.bottom - a.top];
      if (!(w > 0 && h > 0)) return;
      const s = Math.max((e.x1 - e.x0) / w, (e.y1 - e.y0) / h);
      const [cx, cy] = [(e.x0 + e.x1) / 2, (e.y0 + e.y1) / 2];
      const { x: X, y: Y } = c.options.scales;
      const want = [cx - s * w / 2, cx + s * w / 2, cy - s * h / 2, cy + s * h / 2];
      const have = [X.min, X.max, Y.min, Y.max];
      if (want.every((v, i) => Math.abs(v - have[i]) < s * 0.5)) return;
      [X.min, X.max, Y.min, Y.max] = want;
      c.update('none');
    }
  }

  // Keeps extent e at equal scale after every update (first draw and resizes).
  const equalPlugin = (e) => ({
    id: 'rmsEqual',
    afterUpdate(c) {
      if (c.$rmsBusy) return;
      c.$rmsBusy = true;
      try { equalize(c, e); } finally { c.$rmsBusy = false; }
    },
  });

  // Draws the dataset's markerLabel beside each of its points.
  const labelPlugin = {
    id: 'rmsLabels',
    afterDatasetsDraw(c) {
      c.data.datasets.forEach((ds, i) => {
        if (!ds.markerLabel || !c.isDatasetVisible(i)) return;
        c.ctx.save();
        Object.assign(c.ctx, { fillStyle: ds.borderColor, font: 'bold 12px sans-serif' });
        c.getDatasetMeta(i).data.forEach((el) => c.ctx.fillText(ds.markerLabel, el.x + 8, el.y - 6));
        c.ctx.restore();
      });
    },
  };

  // Replaces a linear scale's ticks by round multiples of a 1-2-5 step inside [min, max]; the equal
  // scale's odd min and max get no label of their own.
  function niceTicks(sc) {
    const px = sc.isHorizontal() ? sc.width : sc.height;
    const raw = (sc.max - sc.min) / Math.max(2, Math.floor(px / (sc.isHorizontal() ? 90 : 45)));
    if (!(raw > 0)) return;
    const p = Math.pow(10, Math.floor(Math.log10(raw)));
    const step = p * [1, 2, 5, 10].find((k) => k * p >= raw);
    const ticks = [];
    for (let k = Math.ceil(sc.min / step - 1e-9); k * step <= sc.max + step * 1e-9; k++) ticks.push({ value: k * step });
    sc.ticks = ticks;
  }

  function extent(datasets) {
    const [xs, ys] = [[], []];
    datasets.forEach((d) => d.data.forEach((p) => {
      if (num(p.x) && num(p.y)) { xs.push(p.x); ys.push(p.y); }
    }));
    if (!xs.length) return null;
    const pad = Math.max(1, 0.04 * Math.max(hi(xs) - lo(xs), hi(ys) - lo(ys)));
    return { x0: lo(xs) - pad, x1: hi(xs) + pad, y0: lo(ys) - pad, y1: hi(ys) + pad };
  }

  // The path of the end effector by mode, the bay and the CAE outlined, the goals marked: X against axis b.
  function pathDatasets(b) {
    const P = arr(S.p_ft);
    const pt = (i) => (Array.isArray(P[i]) ? { x: P[i][0], y: P[i][b] } : null);
    const idx = pick(P.length, MAX_PATH);
    const ds = modesPresent(P.length).map((m) => ({
      label: MODE_NAME[m], data: runs(idx, m, pt), borderColor: MODE_COLOR[m], backgroundColor: MODE_COLOR[m],
      showLine: true, borderWidth: 1.5, pointRadius: P.length > 1 ? 0 : 4, spanGaps: false,
    })).filter((d) => d.data.length);
    [['cargo bay', G.bay, '#555555'], ['CAE module', G.cae, '#9467bd']].forEach(([label, box, col]) => {
      const r = rect(box, 'x', b === 1 ? 'y' : 'z');
      if (r) ds.push({ label, data: r, borderColor: col, backgroundColor: 'transparent', showLine: true, pointRadius: 0,
        borderWidth: 1.5, borderDash: [6, 3] });
    });
    [['receptacle', G.receptacle_ft, '#d62728', 'crossRot'], ['port', G.port_ft, '#8c564b', 'rectRot']]
      .forEach(([label, p, col, style]) => {
        if (!Array.isArray(p) || !num(p[0]) || !num(p[b])) return;
        ds.push({ label, markerLabel: label, data: [{ x: p[0], y: p[b] }], borderColor: col, backgroundColor: col,
          pointStyle: style, pointRadius: 7, borderWidth: 2 });
      });
    return ds;
  }

  // A path view at equal scale, its canvas's aspect ratio fixed from the extent.
  function pathView(title, b, bName) {
    const ds = pathDatasets(b);
    const e = extent(ds);
    if (!e) return;
    const aspect = Math.min(3, Math.max(1.2, (e.x1 - e.x0) / (e.y1 - e.y0)));
    const ft = (c) => c.dataset.label + ': (' + c.parsed.x.toFixed(2) + ', ' + c.parsed.y.toFixed(2) + ') ft';
    made.push(new Chart(section(title, null).canvas, {
      type: 'scatter', data: { datasets: ds }, plugins: [equalPlugin(e), labelPlugin],
      options: {
        animation: false, responsive: true, maintainAspectRatio: true, aspectRatio: aspect,
        scales: {
          x: { type: 'linear', min: e.x0, max: e.x1, afterBuildTicks: niceTicks, title: titled('X (along the bay), ft') },
          y: { type: 'linear', min: e.y0, max: e.y1, afterBuildTicks: niceTicks, title: titled(bName) },
        },
        plugins: { legend: { labels: { boxWidth: 14 } }, tooltip: { callbacks: { label: ft } } },
      },
    }));
  }

  // One line per column of rows (arrays of numbers) against session time.
  function columnLines(rows, names) {
    const idx = pick(Math.min(T.length, rows.length), MAX_TIME);
    return names.map((name, k) => ({
      label: name,
      data: runs(idx, null, (i) => ({ x: T[i], y: Array.isArray(rows[i]) ? rows[i][k] : null })),
      borderColor: PALETTE[k % PALETTE.length], backgroundColor: PALETTE[k % PALETTE.length],
    }));
  }

  function jointChart() {
    const J = arr(S.joints_deg);
    if (!J.length || !T.length) return;
    const names = arr(S.joint_names).length ? S.joint_names
      : ['shoulder yaw', 'shoulder pitch', 'elbow pitch', 'wrist pitch', 'wrist yaw', 'wrist roll'];
    timeChart(section('Joint angles', 320).canvas,
      { type: 'line', data: { datasets: columnLines(J, names) }, options: timeOptions('joint angle, deg') });
  }

  // The hand controllers' commanded rates: x, y, z on the left axis in
  // ft/s, roll, pitch, yaw (and the single joint's rate) on the right in
  // deg/s, each column's unit as the data names it; a column never moved
  // is left out.
  function inputChart() {
    const inp = S.inputs;
    const V = inp && arr(inp.values);
    const sec = section('Operator inputs', 300);
    if (!V || !V.length || !T.length) return note(sec, 'no hand-controller inputs (autopilot or timeline)');
    const names = arr(inp.names).length ? inp.names : ['x', 'y', 'z', 'roll', 'pitch', 'yaw'];
    const units = arr(inp.units);
    const unit = (k) => units[k] || (k < 3 ? 'ft/s' : 'deg/s');
    const moved = (k) => V.some((row) => Array.isArray(row) && num(row[k]) && row[k] !== 0);
    const ds = columnLines(V, names.map((n, k) => n + ', ' + unit(k)))
      .map((d, k) => Object.assign(d, { yAxisID: unit(k) === 'ft/s' ? 'y' : 'y1' }))
      .filter((d, k) => moved(k));
    if (!ds.length) return note(sec, 'the hand controllers commanded no motion');
    const o = timeOptions('commanded rate, ft/s (x, y, z)');
    o.scales.y1 = { position: 'right', grid: { drawOnChartArea: false },
      title: titled('commanded rate, deg/s (roll, pitch, yaw, single joint)') };
    timeChart(sec.canvas, { type: 'line', data: { datasets: ds }, options: o });
  }

  function goalChart() {
    const D = arr(S.distance_to_goal_ft);
    const K = arr(S.dock_angle_deg);
    if (!T.length || (!D.some(num) && !K.some(num))) return;
    const idx = pick(T.length, MAX_TIME);
    const ds = modesPresent(T.length).map((m) => ({
      label: m === 1 ? 'Mode 1: end effector to the grasp, ft' : MODE_NAME[m] + ': probe tip to the port, ft',
      data: runs(idx, m, (i) => ({ x: T[i], y: D[i] })), borderColor: MODE_COLOR[m], backgroundColor: MODE_COLOR[m],
      spanGaps: false, yAxisID: 'y',
    })).filter((d) => d.data.length);
    const ang = runs(idx, null, (i) => ({ x: T[i], y: K[i] }));
    if (ang.length) {
      ds.push({ label: 'dock angle, deg (Modes 2-3)', data: ang, borderColor: '#444', backgroundColor: 'transparent',
        borderDash: [5, 3], borderWidth: 1.2, spanGaps: false, yAxisID: 'y1' });
    }
    const o = timeOptions('distance to goal, ft');
    o.scales.y.beginAtZero = true;
    o.scales.y1 = { position: 'right', display: 'auto', beginAtZero: true, grid: { drawOnChartArea: false },
      title: titled('dock angle, deg') };
    timeChart(section('Distance to goal and dock angle', 320).canvas, { type: 'line', data: { datasets: ds }, options: o });
  }

  // Per kind present: its events as points on row y, and their durations as thick segments.
  function eventDatasets(E, rows) {
    const ds = [];
    rows.forEach((kind, y) => {
      const col = KIND_COLOR[kind] || PALETTE[y % PALETTE.length];
      const mine = E.filter((e) => String(e.kind) === kind);
      const bars = [];
      mine.filter((e) => num(e.duration_s) && e.duration_s > 0).forEach((e) => {
        bars.push({ x: e.t_s, y, e }, { x: e.t_s + e.duration_s, y, e }, { x: e.t_s + e.duration_s, y: null });
      });
      if (bars.length) {
        ds.push({ label: kind + ' (duration)', data: bars, showLine: true, spanGaps: false, borderWidth: 8,
          borderColor: col + '66', backgroundColor: col + '66', pointRadius: 0, borderCapStyle: 'butt' });
      }
      if (mine.length) {
        ds.push({ label: kind, data: mine.map((e) => ({ x: e.t_s, y, e })), borderColor: col, backgroundColor: col,
          pointRadius: 5, pointHoverRadius: 7, clip: 8 });
      }
    });
    return ds;
  }

  function eventLabel(c) {
    const e = c.raw.e;
    if (!e) return '';
    const d = num(e.duration_s) ? ', ' + e.duration_s.toFixed(2) + ' s' : '';
    return String(e.kind) + ' at ' + e.t_s.toFixed(2) + ' s' + d + ': ' + (e.text || '');
  }

  // Events on one row per kind against session time.
  function eventChart() {
    const E = arr(R.events).filter((e) => e && num(e.t_s));
    const sec = section('Event timeline', null);
    if (!E.length) return note(sec, 'no events');
    const extra = E.map((e) => String(e.kind)).filter((k, i, a) => KINDS.indexOf(k) < 0 && a.indexOf(k) === i);
    const rows = KINDS.concat(extra);
    sec.box.style.height = (rows.length * 30 + 90) + 'px';
    const o = timeOptions('');
    delete o.parsing;
    o.interaction = { mode: 'nearest', intersect: true };
    o.scales.y = { type: 'linear', min: -0.5, max: rows.length - 0.5, reverse: true,
      afterBuildTicks: (sc) => { sc.ticks = rows.map((_, i) => ({ value: i })); }, ticks: { callback: (v) => rows[v] || '' } };
    o.plugins.legend = { display: false };
    o.plugins.tooltip = { callbacks: { label: eventLabel } };
    timeChart(sec.canvas, { type: 'scatter', data: { datasets: eventDatasets(E, rows) }, options: o });
  }

  function main() {
    if (!document.getElementById('rms-charts')) el('div', { id: 'rms-charts' }, document.body);
    const parts = [
      () => pathView('End effector path, top view (X-Y)', 1, 'Y (across), ft'),
      () => pathView('End effector path, side view (X-Z)', 2, 'Z (up), ft'),
      jointChart, inputChart, goalChart, eventChart,
    ];
    if (typeof Chart === 'undefined') errors.push('Chart.js is not loaded');
    else parts.forEach((f) => {
      try { f(); } catch (e) { errors.push(String(e)); console.error('rms report chart:', e); }
    });
    document.body.dataset.chartsRendered = String(made.length);
    if (errors.length) document.body.dataset.chartsError = errors.join('; ');
  }

  if (document.readyState === 'loading') document.addEventListener('DOMContentLoaded', main);
  else main();
})();

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
  const T = arr(S.t_s);
  const M = arr(S.mode);
  const A = arr(S.attempt);
  const modeAt = (i) => ([1, 2, 3].indexOf(M[i]) >= 0 ? M[i] : 0);
  const keyAt = (i) => modeAt(i) + '/' + A[i];

  // Evenly picked indices of 0..n-1, keeping both samples around every mode or attempt change.
  function pick(n, max) {
    const step = Math.max(1, Math.ceil(n / max));
    const out = [];
    for (let i = 0; i < n; i++) {
      if (i % step === 0 || i === n - 1 || keyAt(i) !== keyAt(i - 1) || keyAt(i) !== keyAt(i + 1)) out.push(i);
    }
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
      const prev = idx[last];
      const broken = last !== j - 1 || keyAt(prev) !== keyAt(i);
      if (out.length && broken) out.push({ x: p.x, y: null });
      out.push(p);
      last = j;
    });
    return out;
  }

  function modesPresent(n) {
    const seen = {};
    for (let i = 0; i < n; i++) seen[modeAt(i)] = true;
    return [0, 1, 2, 3].filter((m) => seen[m]);
  }

  // A titled section holding a canvas (fixed height, or fixed aspect ratio when height is null).
  function section(title, height) {
    const root = document.getElementById('rms-charts');
    const div = document.createElement('div');
    div.className = 'rms-chart';
    const h = document.createElement('h3');
    h.textContent = title;
    div.appendChild(h);
    const box = document.createElement('div');
    box.style.position = 'relative';
    if (height) box.style.height = height + 'px';
    const canvas = document.createElement('canvas');
    box.appendChild(canvas);
    div.appendChild(box);
    root.appendChild(div);
    return { div, box, canvas };
  }

  function note(sec, text) {
    sec.box.remove();
    const p = document.createElement('p');
    p.className = 'rms-chart-note';
    p.textContent = text;
    sec.div.appendChild(p);
  }

  // Session time range, including the ends of timed events.
  function timeRange() {
    const ts = T.filter(num);
    arr(R.events).forEach((e) => {
      if (num(e.t_s)) ts.push(e.t_s + (num(e.duration_s) ? e.duration_s : 0));
    });
    if (!ts.length) return { min: 0, max: 1 };
    const lo = Math.min(...ts);
    const hi = Math.max(...ts);
    return { min: lo, max: hi > lo ? hi : lo + 1 };
  }

  // Shades every other attempt and draws a dashed line and label at each attempt start.
  const attemptPlugin = {
    id: 'rmsAttempts',
    beforeDatasetsDraw(c) {
      const list = arr(R.attempts).filter((a) => a && num(a.start_s));
      const x = c.scales.x;
      const a = c.chartArea;
      if (list.length < 2 || !x || !a) return;
      const ctx = c.ctx;
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
        ctx.strokeStyle = '#666';
        ctx.setLineDash([4, 3]);
        ctx.beginPath();
        ctx.moveTo(x0, a.top);
        ctx.lineTo(x0, a.bottom);
        ctx.stroke();
        ctx.fillStyle = '#444';
        ctx.font = '11px sans-serif';
        ctx.fillText('attempt ' + (at.index != null ? at.index : k + 1), x0 + 4, a.top + 12);
      });
      ctx.restore();
    },
  };

  function timeOptions(ytitle) {
    const r = timeRange();
    return {
      animation: false, parsing: false, normalized: true, responsive: true, maintainAspectRatio: false,
      interaction: { mode: 'nearest', axis: 'x', intersect: false },
      elements: { point: { radius: T.length > 1 ? 0 : 3 }, line: { borderWidth: 1.5 } },
      scales: {
        x: { type: 'linear', min: r.min, max: r.max, title: { display: true, text: 'session time, s' } },
        y: { title: { display: true, text: ytitle } },
      },
      plugins: { legend: { labels: { boxWidth: 14 } } },
    };
  }

  // A chart against session time, with the attempts marked.
  function timeChart(canvas, config) {
    config.plugins = [attemptPlugin];
    made.push(new Chart(canvas, config));
  }

  // --- path views -------------------------------------------------------------------------------

  function rect(box, a, b) {
    const u = box && box[a];
    const v = box && box[b];
    if (!Array.isArray(u) || !Array.isArray(v) || ![u[0], u[1], v[0], v[1]].every(num)) return null;
    return [{ x: u[0], y: v[0] }, { x: u[1], y: v[0] }, { x: u[1], y: v[1] }, { x: u[0], y: v[1] }, { x: u[0], y: v[0] }];
  }

  // Widens the axis ranges of c so that one ft is the same number of pixels on both axes.
  function equalize(c, e) {
    for (let k = 0; k < 4; k++) {
      const a = c.chartArea;
      const w = a.right - a.left;
      const h = a.bottom - a.top;
      if (!(w > 0 && h > 0)) return;
      const s = Math.max((e.x1 - e.x0) / w, (e.y1 - e.y0) / h);
      const cx = (e.x0 + e.x1) / 2;
      const cy = (e.y0 + e.y1) / 2;
      const X = c.options.scales.x;
      const Y = c.options.scales.y;
      const want = [cx - s * w / 2, cx + s * w / 2, cy - s * h / 2, cy + s * h / 2];
      const have = [X.min, X.max, Y.min, Y.max];
      if (want.every((v, i) => Math.abs(v - have[i]) < s * 0.5)) return;
      [X.min, X.max, Y.min, Y.max] = want;
      c.update('none');
    }
  }

  // Keeps extent e at equal scale after every update (first draw and resizes).
  function equalPlugin(e) {
    let busy = false;
    return {
      id: 'rmsEqual',
      afterUpdate(c) {
        if (busy) return;
        busy = true;
        try { equalize(c, e); } finally { busy = false; }
      },
    };
  }

  // Draws the dataset's markerLabel beside each of its points.
  const labelPlugin = {
    id: 'rmsLabels',
    afterDatasetsDraw(c) {
      c.data.datasets.forEach((ds, i) => {
        if (!ds.markerLabel || !c.isDatasetVisible(i)) return;
        c.getDatasetMeta(i).data.forEach((el) => {
          c.ctx.save();
          c.ctx.fillStyle = ds.borderColor;
          c.ctx.font = 'bold 12px sans-serif';
          c.ctx.fillText(ds.markerLabel, el.x + 8, el.y - 6);
          c.ctx.restore();
        });
      });
    },
  };

  // Tick label, blank for the odd edge ticks that the equal scale puts off the step grid.
  function gridTick(v, i, ticks) {
    const step = ticks.length > 2 ? ticks[2].value - ticks[1].value : 0;
    const edge = i === 0 || i === ticks.length - 1;
    if (edge && step > 0 && Math.abs(v / step - Math.round(v / step)) > 1e-6) return '';
    return Chart.Ticks.formatters.numeric.call(this, v, i, ticks);
  }

  function extent(datasets) {
    const xs = [];
    const ys = [];
    datasets.forEach((d) => d.data.forEach((p) => {
      if (num(p.x) && num(p.y)) { xs.push(p.x); ys.push(p.y); }
    }));
    if (!xs.length) return null;
    const e = { x0: Math.min(...xs), x1: Math.max(...xs), y0: Math.min(...ys), y1: Math.max(...ys) };
    const pad = Math.max(1, 0.04 * Math.max(e.x1 - e.x0, e.y1 - e.y0));
    return { x0: e.x0 - pad, x1: e.x1 + pad, y0: e.y0 - pad, y1: e.y1 + pad };
  }

  function pathView(title, b, bName) {
    const P = arr(S.p_ft);
    const pt = (i) => (Array.isArray(P[i]) ? { x: P[i][0], y: P[i][b] } : null);
    const idx = pick(P.length, MAX_PATH);
    const ds = modesPresent(P.length).map((m) => ({
      label: MODE_NAME[m], data: runs(idx, m, pt), borderColor: MODE_COLOR[m], backgroundColor: MODE_COLOR[m],
      showLine: true, borderWidth: 1.5, pointRadius: P.length > 1 ? 0 : 4, spanGaps: false,
    })).filter((d) => d.data.length);
    [['cargo bay', G.bay, '#555555'], ['CAE module', G.cae, '#9467bd']].forEach(([label, box, col]) => {
      const r = rect(box, 'x', b === 1 ? 'y' : 'z');
      if (r) ds.push({ label, data: r, borderColor: col, backgroundColor: col, showLine: true, pointRadius: 0,
        borderWidth: 1.5, borderDash: [6, 3] });
    });
    [['receptacle', G.receptacle_ft, '#d62728', 'crossRot'], ['port', G.port_ft, '#8c564b', 'rectRot']]
      .forEach(([label, p, col, style]) => {
        if (Array.isArray(p) && num(p[0]) && num(p[b])) {
          ds.push({ label, markerLabel: label, data: [{ x: p[0], y: p[b] }], borderColor: col, backgroundColor: col,
            pointStyle: style, pointRadius: 7, borderWidth: 2 });
        }
      });
    const e = extent(ds);
    if (!e) return;
    const sec = section(title, null);
    const aspect = Math.min(3, Math.max(1.2, (e.x1 - e.x0) / (e.y1 - e.y0)));
    made.push(new Chart(sec.canvas, {
      type: 'scatter',
      data: { datasets: ds },
      plugins: [equalPlugin(e), labelPlugin],
      options: {
        animation: false, responsive: true, maintainAspectRatio: true, aspectRatio: aspect,
        scales: {
          x: { type: 'linear', min: e.x0, max: e.x1, ticks: { callback: gridTick },
            title: { display: true, text: 'X (along the bay), ft' } },
          y: { type: 'linear', min: e.y0, max: e.y1, ticks: { callback: gridTick },
            title: { display: true, text: bName } },
        },
        plugins: {
          legend: { labels: { boxWidth: 14 } },
          tooltip: { callbacks: { label: (c) => c.dataset.label + ': (' + c.parsed.x.toFixed(2) + ', ' +
            c.parsed.y.toFixed(2) + ') ft' } },
        },
      },
    }));
  }

  // --- time plots -------------------------------------------------------------------------------

  // One line per column of rows (arrays of numbers) against session time.
  function columnLines(rows, names, unit) {
    const idx = pick(Math.min(T.length, rows.length), MAX_TIME);
    return names.map((name, k) => ({
      label: name + (unit ? ', ' + unit : ''),
      data: runs(idx, null, (i) => ({ x: T[i], y: Array.isArray(rows[i]) ? rows[i][k] : null })),
      borderColor: PALETTE[k % PALETTE.length], backgroundColor: PALETTE[k % PALETTE.length],
    }));
  }

  function jointChart() {
    const J = arr(S.joints_deg);
    if (!J.length || !T.length) return;
    const names = arr(S.joint_names).length ? S.joint_names
      : ['shoulder yaw', 'shoulder pitch', 'elbow pitch', 'wrist pitch', 'wrist yaw', 'wrist roll'];
    const sec = section('Joint angles', 320);
    timeChart(sec.canvas, { type: 'line', data: { datasets: columnLines(J, names, '') }, options: timeOptions('joint angle, deg') });
  }

  function inputChart() {
    const inp = S.inputs;
    const V = inp && arr(inp.values);
    const sec = section('Operator inputs', 300);
    if (!V || !V.length || !T.length) {
      note(sec, 'no hand-controller inputs (autopilot or timeline)');
      return;
    }
    const names = arr(inp.names).length ? inp.names : ['x', 'y', 'z', 'roll', 'pitch', 'yaw'];
    const o = timeOptions('hand controller, ' + (inp.unit || 'fraction of full rate (-1..1)'));
    Object.assign(o.scales.y, { suggestedMin: -1, suggestedMax: 1 });
    timeChart(sec.canvas, { type: 'line', data: { datasets: columnLines(V, names, '') }, options: o });
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
      ds.push({ label: 'dock angle, deg (Modes 2-3)', data: ang, borderColor: '#444', backgroundColor: '#444',
        borderDash: [5, 3], borderWidth: 1.2, spanGaps: false, yAxisID: 'y1' });
    }
    const o = timeOptions('distance to goal, ft');
    o.scales.y.beginAtZero = true;
    o.scales.y1 = { position: 'right', display: 'auto', beginAtZero: true, grid: { drawOnChartArea: false },
      title: { display: true, text: 'dock angle, deg' } };
    const sec = section('Distance to goal and dock angle', 320);
    timeChart(sec.canvas, { type: 'line', data: { datasets: ds }, options: o });
  }

  // --- event timeline ---------------------------------------------------------------------------

  function eventChart() {
    const E = arr(R.events).filter((e) => e && num(e.t_s));
    const sec = section('Event timeline', null);
    if (!E.length) {
      note(sec, 'no events');
      return;
    }
    const rows = KINDS.concat(E.map((e) => String(e.kind)).filter((k, i, a) => KINDS.indexOf(k) < 0 && a.indexOf(k) === i));
    sec.box.style.height = (rows.length * 30 + 90) + 'px';
    const ds = [];
    rows.forEach((kind, y) => {
      const col = KIND_COLOR[kind] || PALETTE[y % PALETTE.length];
      const mine = E.filter((e) => String(e.kind) === kind);
      if (!mine.length) return;
      const bars = [];
      mine.filter((e) => num(e.duration_s) && e.duration_s > 0).forEach((e) => {
        bars.push({ x: e.t_s, y, e }, { x: e.t_s + e.duration_s, y, e }, { x: e.t_s + e.duration_s, y: null });
      });
      if (bars.length) {
        ds.push({ label: kind + ' (duration)', data: bars, showLine: true, spanGaps: false, borderWidth: 8,
          borderColor: col + '66', backgroundColor: col + '66', pointRadius: 0, borderCapStyle: 'butt' });
      }
      ds.push({ label: kind, data: mine.map((e) => ({ x: e.t_s, y, e })), borderColor: col, backgroundColor: col,
        pointRadius: 5, pointHoverRadius: 7 });
    });
    const o = timeOptions('');
    delete o.parsing;
    o.interaction = { mode: 'nearest', intersect: true };
    o.scales.y = { type: 'linear', min: -0.5, max: rows.length - 0.5, reverse: true,
      afterBuildTicks: (s) => { s.ticks = rows.map((_, i) => ({ value: i })); },
      ticks: { callback: (v) => rows[v] || '' } };
    o.plugins.legend = { display: false };
    o.plugins.tooltip = { callbacks: { label: (c) => {
      const e = c.raw.e || {};
      const d = num(e.duration_s) ? ', ' + e.duration_s.toFixed(2) + ' s' : '';
      return String(e.kind) + ' at ' + e.t_s.toFixed(2) + ' s' + d + ': ' + (e.text || '');
    } } };
    timeChart(sec.canvas, { type: 'scatter', data: { datasets: ds }, options: o });
  }

  // --- main ---------------------------------------------------------------------------------------

  function main() {
    if (!document.getElementById('rms-charts')) {
      const div = document.createElement('div');
      div.id = 'rms-charts';
      document.body.appendChild(div);
    }
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

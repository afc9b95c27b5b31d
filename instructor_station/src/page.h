#pragma once
// The instructor's page (docs/instructor.md): one self-contained HTML file,
// no outside scripts. It polls /api/status, /api/events, /api/path and
// /api/plot; fetches each view's next image as soon as the last one was
// shown (the last stays until the next has arrived); sends the controls to
// /api/control and follows each command's answer (/api/command); and in a
// debrief (or when scrubbed back) asks for past frames' views.
namespace rms::instructor_station {

inline constexpr const char* kPageHtml = R"PAGE(<!doctype html>
<html lang="en"><head><meta charset="utf-8">
<meta name="viewport" content="width=device-width, initial-scale=1">
<title>rmslab instructor station</title>
<style>
* { box-sizing: border-box; }
html, body { height: 100%; }
body { font: 13px system-ui, sans-serif; margin: 0; background: #111; color: #ddd; display: flex; flex-direction: column; }
header { padding: 4px 8px; background: #222; display: flex; gap: 4px 14px; align-items: center; flex-wrap: wrap; flex: none; }
h1 { font-size: 14px; margin: 0; }
#banner { font-weight: 700; padding: 2px 10px; border-radius: 3px; background: #2f5f2f; color: #fff; }
#banner.frozen { background: #24528a; } #banner.ended { background: #555; } #banner.lost { background: #8a2424; }
#banner.debrief { background: #5a3d7a; } #banner.waiting { background: #444; }
#note { color: #eb4; }
#timeline { display: flex; gap: 6px; align-items: center; flex-wrap: wrap; padding: 3px 8px; background: #1a1a1a; flex: none; }
#scrub { flex: 1 1 260px; min-width: 160px; }
main { flex: 1 1 auto; min-height: 0; display: grid; grid-template-columns: minmax(0, 34fr) minmax(0, 36fr) minmax(0, 30fr); gap: 6px; padding: 6px; }
.col { min-height: 0; overflow-y: auto; display: flex; flex-direction: column; gap: 6px; }
.pane { background: #1b1b1b; border: 1px solid #333; padding: 4px 6px; }
h2 { font-size: 12px; margin: 0 0 3px 0; color: #bbb; font-weight: 600; }
img.view { width: 100%; background: #000; aspect-ratio: 4 / 3; display: block; object-fit: contain; }
canvas { width: 100%; background: #050505; display: block; }
table { border-collapse: collapse; width: 100%; font-size: 12px; }
td, th { padding: 1px 4px; vertical-align: top; border-bottom: 1px solid #2a2a2a; text-align: left; }
.ok { color: #7d7; } .bad { color: #f77; } .warn { color: #eb4; }
td.bad, span.bad { font-weight: 700; }
#events { max-height: 200px; overflow-y: auto; font: 12px monospace; white-space: pre-wrap; overflow-wrap: anywhere; }
.nowtag { display: none; color: #eb4; font-weight: 400; }
body.scrubbing .nowtag { display: inline; }
.scroll-x { overflow-x: auto; }
#events div.past { color: #999; }
#events div.after { opacity: 0.45; }
button { background: #333; color: #eee; border: 1px solid #666; padding: 3px 9px; margin: 1px; cursor: pointer; font: inherit; }
button:hover { background: #444; } button:disabled { opacity: 0.5; cursor: default; }
input, select { background: #222; color: #eee; border: 1px solid #666; padding: 2px; font: inherit; max-width: 100%; }
#said { font: 12px monospace; min-height: 1.2em; }
.chips span { display: inline-block; margin: 1px 4px 1px 0; padding: 0 4px; border: 1px solid #444; }
.bars { display: grid; grid-template-columns: 2.6em 1fr 3.2em 2.6em 1fr 3.2em; gap: 1px 4px; align-items: center; font-size: 12px; }
.bar { height: 8px; background: #2a2a2a; position: relative; }
.bar i { position: absolute; top: 0; bottom: 0; background: #6af; }
#warnings div { color: #f77; font-weight: 700; }
details summary { cursor: pointer; color: #bbb; font-size: 12px; }
.sr { position: absolute; width: 1px; height: 1px; overflow: hidden; clip: rect(0 0 0 0); }
@media (max-width: 900px) {
  body { display: block; height: auto; }
  header { position: sticky; top: 0; z-index: 2; }
  main { display: block; }
  .col { overflow: visible; margin-bottom: 6px; }
  #events { max-height: 260px; }
  body { font-size: 15px; }
  table, .bars, #events, #said { font-size: 14px; }
}
</style></head>
<body>
<header>
<h1>rmslab instructor</h1>
<span id="banner" class="waiting">CONNECTING</span>
<span id="clock">t -- s</span><span id="mode">no telemetry yet</span>
<span id="flags"></span><span id="note"></span>
<div id="announce" class="sr" role="status" aria-live="polite"></div>
</header>
<nav id="timeline" aria-label="the session's timeline">
<label for="scrub">Session time</label>
<input type="range" id="scrub" min="0" max="0" step="1" value="0">
<span id="cursor">live</span>
<button id="live" aria-label="Back to live">Live</button>
<label for="marktext" class="sr">A note for a mark at the cursor</label>
<input id="marktext" placeholder="note for a mark" size="18" maxlength="500">
<button id="mark">Mark</button>
<span id="branch"></span>
</nav>
<main>
<div class="col">
<div class="pane"><h2>The operator's view <span id="opstation"></span> <span id="frame0"></span></h2>
<img class="view" id="view0" alt="the operator's view, as the trainee sees it"></div>
<div class="pane"><h2><label for="station">Station</label> <select id="station"></select> <span id="frame1"></span></h2>
<img class="view" id="view1" alt="the chosen camera station's view"></div>
</div>
<div class="col">
<div class="pane"><h2>The trainee <span class="nowtag">(now, not at the cursor)</span></h2>
<div id="trainee">no operator state yet</div>
<div class="bars" id="hands" aria-label="the hand controllers' inputs"></div>
<div id="guidance"></div>
<div id="warnings" aria-live="polite"></div></div>
<div class="pane"><h2>Joints (as they are; commanded): a failed part in red <span class="nowtag">(now)</span></h2><table id="joints"></table></div>
<div class="pane"><h2>Acquisition and docking <span class="nowtag">(now)</span></h2><div class="chips" id="acq"></div></div>
<div class="pane"><h2>Distance to the goal and the acquisition margins, ft, against session time</h2>
<canvas id="plot" width="640" height="160" role="img" aria-label="plot of the distance to the goal and the margins against session time"></canvas></div>
<div class="pane"><h2>From above (nose up, starboard right): the end effector's path</h2>
<canvas id="map" width="640" height="230" role="img" aria-label="map of the orbiter, the CAE and the end effector's path"></canvas></div>
</div>
<div class="col">
<div class="pane" id="controls"><h2>Controls</h2>
<button id="freeze">Freeze</button><button id="run">Run</button><button id="step">Step</button>
<button id="reset">Reset</button><br>
<label for="cpname" class="sr">Checkpoint name</label><input id="cpname" placeholder="checkpoint name" size="14"><button id="checkpoint">Checkpoint</button><br>
<label for="cplist" class="sr">Checkpoint to restore</label><select id="cplist"></select><button id="restore">Restore</button>
<h2>Malfunctions</h2>
<label for="mkind" class="sr">Malfunction kind</label><select id="mkind"></select>
<label for="mtarget" class="sr">Joint or camera station</label><select id="mtarget"></select>
<label for="mvalue" class="sr">Value</label><input id="mvalue" size="5">
<span id="munit"></span><button id="inject">Inject</button>
<div id="mlist">none in force</div>
<div id="said" role="status" aria-live="polite"></div>
<h2>Lesson</h2>
<label for="lessonfile">A lesson file (docs/lessons.md): </label><input type="file" id="lessonfile" accept=".toml,text/plain">
<div id="lessonsaid"></div><ol id="lesson"></ol></div>
<div class="pane"><h2><span id="scoretitle">Scorecard (live)</span> <span class="nowtag">(now)</span></h2><table id="score"></table></div>
<div class="pane"><h2>Events</h2><div id="events" tabindex="0" aria-label="the session's events"></div></div>
<div class="pane"><details><summary>Processes: rates, latency, losses</summary><div class="scroll-x"><table id="procs"></table></div></details></div>
</div>
</main>
<script>
"use strict";
const token = new URLSearchParams(location.search).get("token") || "";
const q = (p) => p + (p.includes("?") ? "&" : "?") + "token=" + encodeURIComponent(token);
const $ = (id) => document.getElementById(id);
const fmt = (x, n) => (x === null || x === undefined || Number.isNaN(x)) ? "--" : Number(x).toFixed(n);
let map = null, path = [], pathNext = 0, eventsNext = 0, plot = [], plotNext = 0, instance = null;
let lastStatus = null, events = [], marks = [], failures = 0, debrief = false;
// The cursor: null is live; else a DCP frame (the scrubbed time).
let cursorFrame = null;
// Text from the session's messages (process, host and counter names) is
// never markup.
const esc = (t) => String(t).replace(/[&<>"']/g, (c) => ({"&": "&amp;", "<": "&lt;", ">": "&gt;", '"': "&quot;", "'": "&#39;"})[c]);
const announce = (t) => { $("announce").textContent = t; };

async function getJson(p) {
  const r = await fetch(q(p), {headers: {"X-Rmslab-Token": token}, cache: "no-store"});
  if (!r.ok) throw new Error(p.split("?")[0] + ": " + r.status);
  return r.json();
}

// Each view: the next image is asked for as soon as the last one is shown;
// the last stays until the next has arrived (no broken image between).
function liveView(img, label, viewOf) {
  let n = 0;
  const next = async () => {
    const past = cursorFrame !== null;
    const u = "/api/view?v=" + viewOf() + (past ? "&frame=" + cursorFrame : "") + "&n=" + (n++);
    try {
      const r = await fetch(q(u), {headers: {"X-Rmslab-Token": token}, cache: "no-store"});
      if (r.status === 200) {
        const blob = await r.blob();
        const url = URL.createObjectURL(blob);
        await new Promise((ok) => { img.onload = ok; img.onerror = ok; img.src = url; });
        if (img.dataset.url) URL.revokeObjectURL(img.dataset.url);
        img.dataset.url = url;
        img.dataset.frame = r.headers.get("X-Rmslab-Frame") || "";
        img.dataset.loads = String(Number(img.dataset.loads || 0) + 1);
        label.textContent = "frame " + img.dataset.frame + (past ? " (past)" : "");
        setTimeout(next, past ? 250 : 30);
        return;
      }
    } catch (e) {}
    setTimeout(next, 250);
  };
  next();
}

// A command and its outcome: the processes that act on it answer done or
// refused (RMS_CONTROL_ANSWER); the page says which, never just "sent".
async function control(command, extra) {
  const body = new URLSearchParams(Object.assign({command}, extra || {}));
  const said = $("said");
  let r, j;
  try {
    r = await fetch(q("/api/control"), {method: "POST", body, headers: {"X-Rmslab-Token": token}});
    j = await r.json().catch(() => ({}));
  } catch (e) { said.textContent = command + ": not sent, no connection"; said.className = "bad"; said.dataset.state = "unsent"; return; }
  if (!r.ok) { said.textContent = command + " refused: " + (j.error || r.status); said.className = "bad"; said.dataset.state = "refused"; announce(said.textContent); return; }
  const what = command + (j.name ? " " + j.name : "");
  said.textContent = what + ": waiting for the answer"; said.className = "warn"; said.dataset.state = "pending";
  const end = Date.now() + 8000;
  while (Date.now() < end) {
    await new Promise((ok) => setTimeout(ok, 200));
    const c = await getJson("/api/command?id=" + j.id).catch(() => null);
    if (!c || c.state === "pending") continue;
    const texts = c.answers.map((a) => a.process + ": " + a.text).join("; ");
    said.textContent = what + ": " + (c.state === "done" ? "DONE, " : c.state === "refused" ? "REFUSED, " : "no answer within 3 s from " + c.expected.join(", ")) + texts;
    said.className = c.state === "done" ? "ok" : "bad";
    said.dataset.state = c.state;
    announce(said.textContent);
    refreshCheckpoints();
    return;
  }
  said.textContent = what + ": no answer"; said.className = "bad"; said.dataset.state = "unanswered";
}

function showLesson(l) {
  const list = $("lesson");
  const key = JSON.stringify(l.events || []);
  if (list.dataset.shown !== key) {
    list.dataset.shown = key;
    list.innerHTML = "";
    for (const e of (l.events || [])) {
      const li = document.createElement("li");
      const o = e.outcome, refused = o && o.state === "refused";
      const said = !e.fired ? "  -- to come" : "  -- fired at " + fmt(e.fired_at_s, 1) + " s" +
        (!o ? "" : refused ? ": REFUSED, " + o.answers.filter((x) => !x.done).map((x) => x.text + " (" + x.process + ")").join("; ")
                   : o.state === "done" ? ": done" : ": " + o.state);
      li.textContent = e.text + said;
      li.className = !e.fired ? "" : refused || (o && o.state === "unanswered") ? "bad" : "ok";
      list.appendChild(li);
    }
  }
  if (!lessonSaid) $("lessonsaid").textContent = l.loaded ? l.source : "none loaded";
}

let lessonSaid = false;
async function loadLesson(file) {
  lessonSaid = true;
  const body = new URLSearchParams({text: await file.text(), name: file.name});
  const r = await fetch(q("/api/lesson"), {method: "POST", body, headers: {"X-Rmslab-Token": token}});
  const j = await r.json().catch(() => ({}));
  $("lessonsaid").textContent = r.ok ? j.source :
    ("refused: " + (j.error || (r.status === 413 ? "a lesson file is at most 64 KiB" : r.status)));
  $("lessonsaid").className = r.ok ? "ok" : "bad";
  announce($("lessonsaid").textContent);
  if (r.ok) showLesson(j);
}

async function refreshCheckpoints() {
  try {
    const names = await getJson("/api/checkpoints");
    const sel = $("cplist"), was = sel.value;
    sel.innerHTML = "";
    for (const n of names) { const o = document.createElement("option"); o.textContent = n; sel.appendChild(o); }
    if (names.includes(was)) sel.value = was;
  } catch (e) {}
}

// The malfunction menu, from /api/map's table: the text is the pattern with
// N the target and V the value ("joint 2 drift 0.5"); the station checks it.
function malfunctionMenu() {
  const kind = $("mkind"), target = $("mtarget");
  for (const k of map.malfunctions) {
    const o = document.createElement("option"); o.value = k.name; o.textContent = k.name.replace(/_/g, " "); kind.appendChild(o);
  }
  const chosen = () => map.malfunctions.find((k) => k.name === kind.value);
  const update = () => {
    const k = chosen(), was = target.value;
    target.innerHTML = "";
    const names = map.parts[k.part];
    names.forEach((n, i) => { const o = document.createElement("option"); o.value = String(i + 1); o.textContent = (i + 1) + " " + n; target.appendChild(o); });
    if ([...target.options].some((o) => o.value === was)) target.value = was;
    target.style.display = names.length ? "" : "none";
    $("mvalue").style.display = k.value ? "" : "none";
    $("mvalue").value = String(k.typical);
    $("munit").textContent = k.value ? k.value + " " : "";
  };
  kind.onchange = update;
  update();
  $("inject").onclick = () => {
    const k = chosen();
    control("malfunction", {name: k.pattern.replace("N", target.value).replace("V", $("mvalue").value)});
  };
}

// A malfunction's repair: its part's word, and its number when the part has one.
const repairOf = (t) => { const w = t.split(" "); return (map.parts[w[0]] || []).length ? w[0] + " " + w[1] : w[0]; };

function showMalfunctions(list, off) {
  const div = $("mlist");
  const key = JSON.stringify([list, off]);
  if (div.dataset.shown === key) return;
  div.dataset.shown = key;
  div.innerHTML = list.length ? "" : "none in force";
  for (const t of list) {
    const row = document.createElement("div"), b = document.createElement("button");
    b.textContent = "Repair"; b.setAttribute("aria-label", "Repair " + t); b.onclick = () => control("repair", {name: repairOf(t)});
    b.disabled = off;
    row.className = "bad"; row.appendChild(document.createTextNode(t + " ")); row.appendChild(b);
    div.appendChild(row);
  }
  if (list.length > 1) {
    const b = document.createElement("button"); b.id = "repairall"; b.textContent = "Repair all";
    b.onclick = () => control("repair", {name: "all"}); b.disabled = off; div.appendChild(b);
  }
}

const rate = () => (lastStatus && lastStatus.frame_rate_hz) || 30;
const frameTime = (f) => f / rate();

function drawMap() {
  const c = $("map"), g = c.getContext("2d");
  g.clearRect(0, 0, c.width, c.height);
  if (!map) return;
  let xs = [], ys = [];
  for (const o of map.outlines) for (const p of o.points) { xs.push(p[0]); ys.push(p[1]); }
  for (const p of path) { xs.push(p[1]); ys.push(p[2]); }
  const x0 = Math.min(...xs) - 3, x1 = Math.max(...xs) + 3, y0 = Math.min(...ys) - 3, y1 = Math.max(...ys) + 3;
  const s = Math.min(c.height / (x1 - x0), c.width / (y1 - y0));
  const P = (x, y) => [c.width / 2 + (y - (y0 + y1) / 2) * s, c.height / 2 + (x - (x0 + x1) / 2) * s];
  for (const o of map.outlines) {
    g.beginPath();
    o.points.forEach((p, i) => { const [u, v] = P(p[0], p[1]); i ? g.lineTo(u, v) : g.moveTo(u, v); });
    g.closePath();
    g.strokeStyle = o.group === "cae" ? "#c9a" : "#789";
    g.stroke();
  }
  const until = cursorFrame === null ? Infinity : frameTime(cursorFrame);
  const shown = path.filter((p) => p[0] <= until + 1e-9);
  g.beginPath();
  shown.forEach((p, i) => { const [u, v] = P(p[1], p[2]); i ? g.lineTo(u, v) : g.moveTo(u, v); });
  g.strokeStyle = "#fc3"; g.stroke();
  if (shown.length) {
    const p = shown[shown.length - 1], [u, v] = P(p[1], p[2]);
    g.fillStyle = "#f63"; g.beginPath(); g.arc(u, v, 4, 0, 7); g.fill();
  }
}

// The plot: the distance to the goal (white) and the six margins (colours)
// against session time; events as ticks (mode changes, collisions,
// malfunctions, commands, marks); the cursor as a line.
const marginColours = ["#6af", "#7d7", "#eb4", "#f7a", "#a8f", "#4dd"];
function drawPlot() {
  const c = $("plot"), g = c.getContext("2d");
  g.clearRect(0, 0, c.width, c.height);
  if (!plot.length) return;
  const t0 = plot[0][0], t1 = Math.max(plot[plot.length - 1][0], t0 + 1);
  let lo = -0.5, hi = 2;
  for (const p of plot) {
    if (p[3] !== null) hi = Math.max(hi, Math.min(p[3], 60));
    for (const m of p[4]) if (m !== null) { lo = Math.max(Math.min(lo, m), -5); hi = Math.max(hi, Math.min(m, 60)); }
  }
  const X = (t) => 30 + (t - t0) / (t1 - t0) * (c.width - 36), Y = (v) => c.height - 14 - (v - lo) / (hi - lo) * (c.height - 22);
  g.strokeStyle = "#444"; g.beginPath(); g.moveTo(30, Y(0)); g.lineTo(c.width, Y(0)); g.stroke();
  g.fillStyle = "#aaa"; g.font = "11px sans-serif";
  g.fillText(fmt(hi, 0), 2, 12); g.fillText("0", 2, Y(0) + 4); g.fillText(fmt(t0, 0) + " s", 30, c.height - 2); g.fillText(fmt(t1, 0) + " s", c.width - 40, c.height - 2);
  const line = (get, colour) => {
    g.strokeStyle = colour; g.beginPath(); let on = false;
    for (const p of plot) { const v = get(p); if (v === null || p[2] !== 1 && get !== goal) { on = false; continue; } const [u, w] = [X(p[0]), Y(Math.max(lo, Math.min(hi, v)))]; on ? g.lineTo(u, w) : g.moveTo(u, w); on = true; }
    g.stroke();
  };
  const goal = (p) => p[3];
  for (let i = 0; i < 6; ++i) line((p) => p[4][i], marginColours[i]);
  g.lineWidth = 2; line(goal, "#fff"); g.lineWidth = 1;
  const tick = {mode: "#fff", collision: "#f55", malfunction: "#f90", control: "#6af", mark: "#ff0", acquired: "#7d7", docked: "#7d7"};
  for (const e of events) {
    const col = tick[e.kind]; if (!col || e.session_s < t0) continue;
    g.strokeStyle = col; g.beginPath(); g.moveTo(X(e.session_s), 0); g.lineTo(X(e.session_s), 8); g.stroke();
  }
  for (const m of marks) { g.fillStyle = "#ff0"; g.fillRect(X(m.session_s) - 2, 0, 4, 10); }
  if (cursorFrame !== null) { g.strokeStyle = "#ff0"; g.beginPath(); g.moveTo(X(frameTime(cursorFrame)), 0); g.lineTo(X(frameTime(cursorFrame)), c.height); g.stroke(); }
}

function showBanner(s) {
  const st = s.session || {}, b = $("banner");
  let text = st.state || "WAITING", cls = "";
  if (st.state === "FROZEN") { text = "FROZEN since " + new Date(st.frozen_wall_us / 1000).toLocaleTimeString() + " (t " + fmt(st.frozen_session_s, 1) + " s)"; cls = "frozen"; }
  else if (st.state === "SESSION ENDED") { text = "SESSION ENDED: " + (st.ended_how || ""); cls = "ended"; }
  else if (st.state === "DEBRIEF") { text = "DEBRIEF of a recorded session" + (st.ended_how ? ": " + st.ended_how : ""); cls = "debrief"; }
  else if (st.state === "WAITING") cls = "waiting";
  if (b.textContent !== text) { b.textContent = text; announce(text); }
  b.className = cls;
  debrief = !!st.debrief;
  $("note").textContent = st.restarted ? "STATION RESTARTED: its history recovered from the session's log" : "";
  for (const id of ["freeze", "run", "step", "reset", "checkpoint", "restore", "inject", "cpname", "cplist",
                    "mkind", "mtarget", "mvalue", "lessonfile"]) $(id).disabled = debrief || st.ended;
  if (debrief) for (const n of document.querySelectorAll(".nowtag")) n.textContent = "(at the session's end, not the cursor)";
  $("scoretitle").textContent = debrief ? "Scorecard (the session's)" : st.ended ? "Scorecard (at the end)" : "Scorecard (live)";
}

const rateScale = {};  // the largest rate of each kind commanded so far (the bars' full length)

function showTrainee(s) {
  const o = s.operator;
  if (!o) { $("trainee").textContent = "no operator state yet"; }
  else {
    $("trainee").innerHTML = "<b>" + esc(o.source) + "</b>" + (o.source !== "by hand" ? "" : ": " + esc(o.control_mode) +
      (o.control_mode === "manual augmented" ? ", frame " + esc(o.command_frame) : "") +
      (o.joint ? ", joint " + esc(o.joint) : "") + ", " + esc(o.scale) +
      ", " + o.key_actions + " key presses");
    // The commanded rates (ft/s; deg/s; single joint: the joint's, deg/s), each
    // bar against the largest of its kind commanded so far this session.
    const single = o.control_mode === "single joint";
    const names = single ? ["joint " + (o.joint || ""), "", "", "", "", ""] : ["x", "roll", "y", "pitch", "z", "yaw"];
    const order = [0, 3, 1, 4, 2, 5], units = single ? ["deg/s", "", "", "", "", ""] : ["ft/s", "deg/s", "ft/s", "deg/s", "ft/s", "deg/s"];
    let h = "";
    order.map((k) => o.hand_rate[k] || 0).forEach((v, i) => {
      const kind = single ? "joint" : i % 2 ? "deg" : "ft";
      rateScale[kind] = Math.max(rateScale[kind] || 0, Math.abs(v));
      const f = rateScale[kind] > 0 ? v / rateScale[kind] : 0;
      if (!names[i]) return;
      h += "<span>" + esc(names[i]) + "</span><div class=bar><i style='left:" + (50 + Math.min(0, f) * 50) + "%;width:" + Math.abs(f) * 50 + "%'></i></div><span>" + fmt(v, 2) + " " + units[i] + "</span>";
    });
    $("hands").innerHTML = h;
    const gd = o.guidance;
    $("guidance").innerHTML = gd ? "to " + esc(gd.target) + ": " + fmt(gd.distance_ft, 2) + " ft, " + fmt(gd.angle_deg, 1) +
      " deg (offset " + gd.offset_ft.map((v) => fmt(v, 2)).join(", ") + " ft)" : "no guidance";
  }
  const w = s.warnings || [];
  $("warnings").innerHTML = w.map((t) => "<div>" + esc(t) + "</div>").join("");
}

function showJoints(d, mal) {
  if (!d || !map) return;
  const stuck = (i) => mal.some((t) => t.startsWith("joint " + (i + 1) + " "));
  let rows = "<tr><th>joint</th><th>deg</th><th>commanded</th></tr>";
  map.joints.forEach((n, i) => {
    const bad = Math.abs(d.master_angles_deg[i] - d.slave_angles_deg[i]) > 0.5 || stuck(i);
    rows += "<tr><td>" + (i + 1) + " " + esc(n) + "</td><td" + (bad ? " class=bad" : "") + ">" + fmt(d.slave_angles_deg[i], 1) +
      "</td><td>" + fmt(d.master_angles_deg[i], 1) + "</td></tr>";
  });
  const finger = mal.some((t) => t.startsWith("finger")) || Math.abs(d.master_finger - d.slave_finger) > 0.02;
  rows += "<tr id=fingerrow><td>finger lever</td><td" + (finger ? " class=bad" : "") + ">" + fmt(d.slave_finger, 2) + "</td><td>" + fmt(d.master_finger, 2) + "</td></tr>";
  $("joints").innerHTML = rows;
}

function showAcquisition(d) {
  if (!d) return;
  let h = "";
  if (d.mode === 1) for (const c of d.acquisition_conditions)
    h += "<span class=" + (c.holds ? "ok" : "bad") + ">" + esc(c.name) + " " + fmt(c.margin_ft, 2) + "</span>";
  h += "<span>dock " + fmt(d.dock_distance_ft, 2) + " ft (&le; " + fmt(d.dock_distance_limit_ft, 2) + "), " + fmt(d.dock_angle_deg, 1) + " deg (&le; " + fmt(d.dock_angle_limit_deg, 1) + ")</span>";
  h += "<span>clear of the bay " + fmt(d.bay_clearance_ft, 2) + " ft</span>";
  $("acq").innerHTML = h;
}

function showScore(c) {
  if (!c) return;
  const rows = [["attempt", c.attempts], ["session time", fmt(c.session_s, 1) + " s"],
    ["Mode 1 / 2 / 3", c.mode_s.map((v) => fmt(v, 1)).join(" / ") + " s"], ["collisions", c.collisions + " (" + fmt(c.collision_s, 1) + " s)"],
    ["holds", c.holds], ["malfunctions", c.malfunctions], ["acquired at", c.acquired_at_s === null ? "--" : fmt(c.acquired_at_s, 1) + " s"],
    ["docked at", c.docked_at_s === null ? "--" : fmt(c.docked_at_s, 1) + " s"], ["closest to the port", fmt(c.closest_to_port_ft, 2) + " ft"],
    ["key presses", c.key_actions]];
  $("score").innerHTML = rows.map((r) => "<tr><td>" + r[0] + "</td><td>" + esc(r[1]) + "</td></tr>").join("");
}

function showProcesses(s) {
  let rows = "<tr><th>process</th><th>state</th><th>Hz</th><th>latency p50/p99 ms</th><th>dropped</th></tr>";
  for (const [name, p] of Object.entries(s.processes)) {
    const lat = Object.entries(p.latency).map(([k, v]) => esc(k) + " " + fmt(v.p50_ms, 1) + "/" + fmt(v.p99_ms, 1)).join("<br>");
    rows += "<tr><td>" + esc(name) + "</td><td class=" + (p.state === "running" ? "ok" : "warn") + ">" + esc(p.state) +
      "</td><td>" + fmt(p.rate_hz, 1) + "</td><td>" + lat + "</td><td>" + fmt(p.dropped, 0) + "</td></tr>";
  }
  $("procs").innerHTML = rows;
}

function showStatus(s) {
  if (instance !== null && s.instance !== instance) {
    // The station restarted: it read its history again from the session's
    // log; the lists are read again from the start.
    eventsNext = 0; pathNext = 0; path = []; plotNext = 0; plot = []; events = [];
    $("events").textContent = "";
    announce("the instructor's station restarted: its history read again");
  }
  instance = s.instance;
  lastStatus = s;
  showBanner(s);
  const d = s.dcp;
  $("opstation").textContent = cursorFrame !== null ? "(at the cursor)" : s.camera_station ? "(station " + s.camera_station + ")" : "";
  if (d) {
    $("clock").textContent = "t " + fmt(d.session_s, 1) + " s, frame " + d.frame;
    $("mode").textContent = "MODE " + d.mode;
    $("flags").innerHTML = (d.acquired ? "<span class=ok>ACQUIRED</span> " : "") +
      (d.docked ? "<span class=ok>DOCKED</span> " : "") + (d.held ? "<span class=bad>HELD</span> " : "") +
      (d.collisions ? "<span class=bad>COLLISION " + esc(d.collisions) + "</span>" : "");
  }
  showTrainee(s);
  showJoints(d, s.malfunctions || []);
  showAcquisition(d);
  showScore(s.scorecard);
  showProcesses(s);
  showMalfunctions(s.malfunctions || [], debrief || !!(s.session && s.session.ended));
  const h = s.history, sc = $("scrub");
  if (h) { sc.min = String(h.first_frame); sc.max = String(h.last_frame); if (cursorFrame === null) sc.value = sc.max; }
}

function showEvents(ev) {
  for (const e of ev) {
    events.push(e);
    const line = document.createElement("div");
    line.textContent = fmt(e.session_s, 1).padStart(7) + " s  " + e.text;
    line.dataset.kind = e.kind; line.dataset.t = String(e.session_s);
    if (e.kind === "answer" && / REFUSED, /.test(e.text)) line.className = "bad";
    $("events").appendChild(line);
    eventsNext = e.seq + 1;
    if (e.kind === "station" || e.kind === "failure" || e.kind === "malfunction") announce(e.text);
  }
  if (ev.length && cursorFrame === null) $("events").scrollTop = 1e9;
}

// The events under the cursor: those after it dimmed; the nearest before it in view.
function markCursorEvents() {
  const lines = $("events").children;
  if (cursorFrame === null) { for (const l of lines) l.className = l.className.replace(/\s*after/, ""); return; }
  const t = frameTime(cursorFrame);
  let last = null;
  for (const l of lines) {
    const after = Number(l.dataset.t) > t + 1e-9;
    l.classList.toggle("after", after);
    if (!after) last = l;
  }
  // Scroll the list only, never the page (on a phone the views stay in sight).
  const box = $("events");
  if (last) {
    const lr = last.getBoundingClientRect(), br = box.getBoundingClientRect();
    if (lr.bottom > br.bottom) box.scrollTop += lr.bottom - br.bottom;
    else if (lr.top < br.top) box.scrollTop -= br.top - lr.top;
  }
}

async function poll() {
  try {
    showStatus(await getJson("/api/status"));
    showEvents(await getJson("/api/events?since=" + eventsNext));
    showLesson(await getJson("/api/lesson"));
    const p = await getJson("/api/path?since=" + pathNext);
    path = path.concat(p.points); pathNext = p.next;
    const pl = await getJson("/api/plot?since=" + plotNext);
    plot = plot.concat(pl.points); plotNext = pl.next;
    if (plot.length > 20000) plot = plot.slice(-20000);
    marks = await getJson("/api/marks");
    drawMap(); drawPlot(); markCursorEvents();
    failures = 0;
  } catch (e) {
    // The station is gone or unreachable: said, and tried again.
    ++failures;
    const ended = lastStatus && lastStatus.session && lastStatus.session.ended;
    const b = $("banner");
    const text = ended ? "SESSION ENDED: " + (lastStatus.session.ended_how || "") + " -- the station has closed (for a debrief: scripts/lab debrief " + (lastStatus.session.session_dir || "SESSION") + ")"
                       : "CONNECTION LOST to the instructor's station (" + e.message + "): retrying, attempt " + failures;
    if (b.textContent !== text) { b.textContent = text; announce(text); }
    b.className = ended ? "ended" : "lost";
  }
  setTimeout(poll, failures ? Math.min(5000, 500 * failures) : 250);
}

function scrubTo(frame) {
  cursorFrame = frame;
  document.body.classList.toggle("scrubbing", frame !== null);
  $("cursor").textContent = frame === null ? "live" : "t " + fmt(frameTime(frame), 1) + " s (frame " + frame + ")";
  // Initial conditions from this instant: a new session branched from it
  // (docs/sessions.md "Branching"), its pose the one the views show.
  const dir = lastStatus && lastStatus.session && lastStatus.session.session_dir;
  $("branch").textContent = frame !== null && dir ? "start a session from here: scripts/lab demo --from " + dir + "@f" + frame : "";
  drawMap(); drawPlot(); markCursorEvents();
}

async function placeMark() {
  const text = $("marktext").value.trim();
  if (!text) { $("said").textContent = "a mark needs a note"; $("said").className = "bad"; return; }
  const f = cursorFrame !== null ? cursorFrame : Number($("scrub").max);
  const body = new URLSearchParams({text, t: String(frameTime(f))});
  const r = await fetch(q("/api/mark"), {method: "POST", body, headers: {"X-Rmslab-Token": token}});
  const j = await r.json().catch(() => ({}));
  $("said").textContent = r.ok ? "marked at " + fmt(j.session_s, 1) + " s: " + j.text : "mark refused: " + (j.error || r.status);
  $("said").className = r.ok ? "ok" : "bad";
  announce($("said").textContent);
  if (r.ok) $("marktext").value = "";
}

async function start() {
  map = await getJson("/api/map").catch(() => null);
  const sel = $("station");
  (map ? map.stations : ["1", "2", "3", "4", "5", "6", "7", "8"]).forEach((n, i) => {
    const o = document.createElement("option"); o.value = String(i + 1); o.textContent = (i + 1) + " " + n; sel.appendChild(o);
  });
  liveView($("view0"), $("frame0"), () => 0);
  liveView($("view1"), $("frame1"), () => sel.value);
  $("freeze").onclick = () => control("freeze");
  $("run").onclick = () => control("run");
  $("step").onclick = () => control("step");
  $("reset").onclick = () => control("reset");
  $("checkpoint").onclick = () => {
    if (!$("cpname").value.trim()) { $("said").textContent = "checkpoint: give it a name"; $("said").className = "bad"; $("said").dataset.state = "refused"; return; }
    control("checkpoint", {name: $("cpname").value});
  };
  $("restore").onclick = () => control("restore", {name: $("cplist").value});
  $("scrub").oninput = (e) => scrubTo(Number(e.target.value) >= Number(e.target.max) && !debrief ? null : Number(e.target.value));
  $("live").onclick = () => { $("scrub").value = $("scrub").max; scrubTo(null); };
  $("mark").onclick = placeMark;
  if (map) malfunctionMenu();
  $("lessonfile").onchange = (e) => { if (e.target.files[0]) loadLesson(e.target.files[0]); };
  refreshCheckpoints();
  poll();
}
start();
</script></body></html>
)PAGE";

}  // namespace rms::instructor_station

#pragma once
// The instructor's page (docs/instructor.md): one self-contained HTML file,
// no outside scripts. It polls /api/status, /api/events and /api/path,
// reloads each view's image as soon as the last one arrived, and sends the
// controls to /api/control with the token from its own URL.
namespace rms::instructor_station {

inline constexpr const char* kPageHtml = R"PAGE(<!doctype html>
<html lang="en"><head><meta charset="utf-8">
<title>rmslab instructor station</title>
<style>
body { font: 14px system-ui, sans-serif; margin: 0; background: #111; color: #ddd; }
header { padding: 6px 12px; background: #222; display: flex; gap: 18px; align-items: baseline; flex-wrap: wrap; }
header b { font-size: 16px; }
main { display: grid; grid-template-columns: 1fr 1fr 440px; gap: 10px; padding: 10px; }
.pane { background: #1b1b1b; border: 1px solid #333; padding: 6px; }
.pane h2 { font-size: 13px; margin: 0 0 6px 0; color: #aaa; font-weight: 600; }
img.view { width: 100%; image-rendering: auto; background: #000; aspect-ratio: 4 / 3; display: block; }
canvas { width: 100%; background: #050505; display: block; }
table { border-collapse: collapse; width: 100%; font-size: 12px; }
td, th { padding: 2px 4px; vertical-align: top; border-bottom: 1px solid #2a2a2a; text-align: left; }
.ok { color: #6c6; } .bad { color: #e66; } .warn { color: #eb4; }
#events { height: 260px; overflow-y: auto; font: 12px monospace; white-space: pre-wrap; }
button { background: #333; color: #eee; border: 1px solid #555; padding: 4px 10px; margin: 2px; cursor: pointer; }
button:hover { background: #444; }
input, select { background: #222; color: #eee; border: 1px solid #555; padding: 3px; }
#said { font: 12px monospace; min-height: 1.2em; }
</style></head>
<body>
<header><b>rmslab instructor station</b>
<span id="clock">t -- s</span><span id="mode">no telemetry yet</span>
<span id="flags"></span><span id="collisions"></span><span id="conn"></span></header>
<main>
<div class="pane"><h2>The operator's view <span id="opstation"></span></h2>
<img class="view" id="view0" alt="the operator's view"></div>
<div class="pane"><h2>Station <select id="station"></select> <span id="viewframe"></span></h2>
<img class="view" id="view1" alt="a camera station's view"></div>
<div class="pane"><h2>Controls</h2>
<button id="freeze">Freeze</button><button id="run">Run</button><button id="step">Step</button>
<button id="reset">Reset</button><br>
<input id="cpname" placeholder="checkpoint name" size="16"><button id="checkpoint">Checkpoint</button><br>
<select id="cplist"></select><button id="restore">Restore</button>
<h2>Malfunctions</h2>
<select id="mkind"></select><select id="mtarget"></select><input id="mvalue" size="6">
<span id="munit"></span><button id="inject">Inject</button><br>
<div id="mlist">none in force</div>
<div id="said"></div>
<h2>Lesson</h2>
<label for="lessonfile">A lesson file (docs/lessons.md): </label><input type="file" id="lessonfile" accept=".toml,text/plain">
<div id="lessonsaid"></div><ol id="lesson"></ol>
<h2>Events</h2><div id="events"></div></div>
<div class="pane"><h2>From above: the orbiter, the CAE and the end effector's path (nose up, starboard right)</h2>
<canvas id="map" width="640" height="480"></canvas></div>
<div class="pane"><h2>Acquisition and docking</h2><table id="acq"></table></div>
<div class="pane"><h2>Processes: rates, latency, losses</h2><table id="procs"></table></div>
</main>
<script>
"use strict";
const token = new URLSearchParams(location.search).get("token") || "";
const q = (p) => p + (p.includes("?") ? "&" : "?") + "token=" + encodeURIComponent(token);
const $ = (id) => document.getElementById(id);
const fmt = (x, n) => (x === null || x === undefined) ? "--" : Number(x).toFixed(n);
let map = null, path = [], pathNext = 0, eventsNext = 0, lastStatus = null, instance = null;
// Text from the session's messages (process, host and counter names) is
// never markup.
const esc = (t) => String(t).replace(/[&<>"']/g, (c) => ({"&": "&amp;", "<": "&lt;", ">": "&gt;", '"': "&quot;", "'": "&#39;"})[c]);

async function getJson(p) {
  const r = await fetch(q(p), {headers: {"X-Rmslab-Token": token}, cache: "no-store"});
  if (!r.ok) throw new Error(p + ": " + r.status);
  return r.json();
}

// Each view: the next image is asked for as soon as the last one arrived.
function liveView(img, viewOf) {
  let n = 0;
  const next = () => { img.src = q("/api/view?v=" + viewOf() + "&n=" + (n++)); };
  img.onload = () => { img.dataset.loads = String(Number(img.dataset.loads || 0) + 1); setTimeout(next, 30); };
  img.onerror = () => setTimeout(next, 300);
  next();
}

async function control(command, extra) {
  const body = new URLSearchParams(Object.assign({command}, extra || {}));
  const r = await fetch(q("/api/control"), {method: "POST", body, headers: {"X-Rmslab-Token": token}});
  const j = await r.json().catch(() => ({}));
  $("said").textContent = r.ok ? ("sent " + command + (j.name ? " " + j.name : "")) : ("refused: " + (j.error || r.status));
  $("said").className = r.ok ? "ok" : "bad";
  refreshCheckpoints();
}

// The lesson: each event and whether it fired, when (session time).
function showLesson(l) {
  const list = $("lesson");
  list.innerHTML = "";
  for (const e of (l.events || [])) {
    const li = document.createElement("li");
    li.textContent = e.text + (e.fired ? "  -- fired at " + fmt(e.fired_at_s, 1) + " s" : "  -- to come");
    li.className = e.fired ? "ok" : "";
    list.appendChild(li);
  }
  // (what the last load said stays until the next load: a refusal is not
  // overwritten by the next poll)
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
    const names = k.pattern.startsWith("joint") ? map.joints : k.pattern.startsWith("camera") ? map.stations : [];
    names.forEach((n, i) => { const o = document.createElement("option"); o.value = String(i + 1); o.textContent = (i + 1) + " " + n; target.appendChild(o); });
    if ([...target.options].some((o) => o.value === was)) target.value = was;
    target.style.display = names.length ? "" : "none";
    $("mvalue").style.display = k.value ? "" : "none";
    $("mvalue").value = k.pattern.includes("delayed") ? "500" : "1";
    $("munit").textContent = k.value ? k.value + " " : "";
  };
  kind.onchange = update;
  update();
  $("inject").onclick = () => {
    const k = chosen();
    control("malfunction", {name: k.pattern.replace("N", target.value).replace("V", $("mvalue").value)});
  };
}

// What a malfunction in force is repaired as: "joint 2 stuck" -> "joint 2".
const repairOf = (t) => t.startsWith("joint") || t.startsWith("camera") ? t.split(" ").slice(0, 2).join(" ") : t.split(" ")[0];

function showMalfunctions(list) {
  const div = $("mlist");
  if (div.dataset.shown === JSON.stringify(list)) return;
  div.dataset.shown = JSON.stringify(list);
  div.innerHTML = list.length ? "" : "none in force";
  for (const t of list) {
    const row = document.createElement("div"), b = document.createElement("button");
    b.textContent = "Repair"; b.onclick = () => control("repair", {name: repairOf(t)});
    row.className = "bad"; row.appendChild(document.createTextNode(t + " ")); row.appendChild(b);
    div.appendChild(row);
  }
  if (list.length > 1) {
    const b = document.createElement("button"); b.id = "repairall"; b.textContent = "Repair all";
    b.onclick = () => control("repair", {name: "all"}); div.appendChild(b);
  }
}

function drawMap() {
  const c = $("map"), g = c.getContext("2d");
  g.clearRect(0, 0, c.width, c.height);
  if (!map) return;
  let xs = [], ys = [];
  for (const o of map.outlines) for (const p of o.points) { xs.push(p[0]); ys.push(p[1]); }
  for (const p of path) { xs.push(p[1]); ys.push(p[2]); }
  const x0 = Math.min(...xs) - 3, x1 = Math.max(...xs) + 3, y0 = Math.min(...ys) - 3, y1 = Math.max(...ys) + 3;
  const s = Math.min(c.height / (x1 - x0), c.width / (y1 - y0));
  // Seen from above (R: x aft, y starboard, z up): the nose up the page, starboard right.
  const P = (x, y) => [c.width / 2 + (y - (y0 + y1) / 2) * s, c.height / 2 + (x - (x0 + x1) / 2) * s];
  for (const o of map.outlines) {
    g.beginPath();
    o.points.forEach((p, i) => { const [u, v] = P(p[0], p[1]); i ? g.lineTo(u, v) : g.moveTo(u, v); });
    g.closePath();
    g.strokeStyle = o.group === "cae" ? "#c9a" : "#789";
    g.stroke();
  }
  g.beginPath();
  path.forEach((p, i) => { const [u, v] = P(p[1], p[2]); i ? g.lineTo(u, v) : g.moveTo(u, v); });
  g.strokeStyle = "#fc3"; g.stroke();
  if (path.length) {
    const p = path[path.length - 1], [u, v] = P(p[1], p[2]);
    g.fillStyle = "#f63"; g.beginPath(); g.arc(u, v, 4, 0, 7); g.fill();
  }
}

function showStatus(s) {
  lastStatus = s;
  if (instance !== null && s.instance !== instance) {
    // The station restarted: its events and path begin again.
    eventsNext = 0; pathNext = 0; path = [];
    $("events").textContent = "";
  }
  instance = s.instance;
  const d = s.dcp;
  $("opstation").textContent = s.camera_station ? "(station " + s.camera_station + ")" : "";
  if (d) {
    $("clock").textContent = "t " + fmt(d.session_s, 1) + " s  frame " + d.frame;
    $("mode").textContent = "MODE " + d.mode;
    $("flags").innerHTML = (d.acquired ? "<span class=ok>ACQUIRED</span> " : "not acquired ") +
      (d.docked ? "<span class=ok>DOCKED</span> " : "") + (d.held ? "<span class=bad>HELD</span>" : "");
    $("collisions").innerHTML = d.collisions ? "<span class=bad>collision: " + esc(d.collisions) + "</span>" : "no collision";
    let rows = "<tr><th>condition</th><th>holds</th><th>margin ft</th></tr>";
    for (const c of d.acquisition_conditions)
      rows += d.mode === 1
        ? "<tr><td>" + esc(c.name) + "</td><td class=" + (c.holds ? "ok>yes" : "bad>no") + "</td><td>" + fmt(c.margin_ft, 3) + "</td></tr>"
        : "<tr><td>" + esc(c.name) + "</td><td colspan=2>(Mode 1 only: acquired)</td></tr>";
    rows += "<tr><td>docking distance</td><td></td><td>" + fmt(d.dock_distance_ft, 3) + " (&le; " + fmt(d.dock_distance_limit_ft, 2) + ")</td></tr>";
    rows += "<tr><td>docking angle, deg</td><td></td><td>" + fmt(d.dock_angle_deg, 2) + " (&le; " + fmt(d.dock_angle_limit_deg, 2) + ")</td></tr>";
    rows += "<tr><td>clear of the bay, ft</td><td></td><td>" + fmt(d.bay_clearance_ft, 2) + "</td></tr>";
    // Each joint as commanded and as it is: a failed joint shows here.
    (map ? map.joints : []).forEach((n, i) => {
      const off = Math.abs(d.master_angles_deg[i] - d.slave_angles_deg[i]) > 0.5;
      rows += "<tr><td>joint " + (i + 1) + " " + esc(n) + ", deg</td><td></td><td" + (off ? " class=bad" : "") + ">" +
        fmt(d.slave_angles_deg[i], 1) + " (commanded " + fmt(d.master_angles_deg[i], 1) + ")</td></tr>";
    });
    rows += "<tr><td>finger lever</td><td></td><td>" + fmt(d.slave_finger, 2) + " (commanded " + fmt(d.master_finger, 2) + ")</td></tr>";
    $("acq").innerHTML = rows;
  }
  let rows = "<tr><th>process</th><th>state</th><th>Hz</th><th>latency p50/p99 ms</th><th>dropped</th></tr>";
  for (const [name, p] of Object.entries(s.processes)) {
    const lat = Object.entries(p.latency).map(([k, v]) => esc(k) + " " + fmt(v.p50_ms, 1) + "/" + fmt(v.p99_ms, 1)).join("<br>");
    rows += "<tr><td>" + esc(name) + "</td><td class=" + (p.state === "running" ? "ok" : "warn") + ">" + esc(p.state) +
      "</td><td>" + fmt(p.rate_hz, 1) + "</td><td>" + lat + "</td><td>" + fmt(p.dropped, 0) + "</td></tr>";
  }
  $("procs").innerHTML = rows;
  showMalfunctions(s.malfunctions || []);
}

async function poll() {
  try {
    showStatus(await getJson("/api/status"));
    const ev = await getJson("/api/events?since=" + eventsNext);
    for (const e of ev) {
      const line = document.createElement("div");
      line.textContent = fmt(e.session_s, 1).padStart(7) + " s  " + e.text;
      line.dataset.kind = e.kind;
      $("events").appendChild(line);
      eventsNext = e.seq + 1;
    }
    if (ev.length) $("events").scrollTop = 1e9;
    showLesson(await getJson("/api/lesson"));
    const p = await getJson("/api/path?since=" + pathNext);
    path = path.concat(p.points); pathNext = p.next;
    drawMap();
    $("conn").textContent = "";
  } catch (e) {
    $("conn").innerHTML = "<span class=bad>" + esc(e.message) + "</span>";
  }
  setTimeout(poll, 250);
}

async function start() {
  map = await getJson("/api/map").catch(() => null);
  const sel = $("station");
  (map ? map.stations : ["1", "2", "3", "4", "5", "6", "7", "8"]).forEach((n, i) => {
    const o = document.createElement("option"); o.value = String(i + 1); o.textContent = (i + 1) + " " + n; sel.appendChild(o);
  });
  liveView($("view0"), () => 0);
  liveView($("view1"), () => sel.value);
  $("freeze").onclick = () => control("freeze");
  $("run").onclick = () => control("run");
  $("step").onclick = () => control("step");
  $("reset").onclick = () => control("reset");
  $("checkpoint").onclick = () => control("checkpoint", {name: $("cpname").value});
  $("restore").onclick = () => control("restore", {name: $("cplist").value});
  if (map) malfunctionMenu();
  $("lessonfile").onchange = (e) => { if (e.target.files[0]) loadLesson(e.target.files[0]); };
  refreshCheckpoints();
  poll();
}
start();
</script></body></html>
)PAGE";

}  // namespace rms::instructor_station

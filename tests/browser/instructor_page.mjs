// The instructor's page in a real browser (docs/instructor.md "Tests"):
// headless Chromium from Debian, driven by puppeteer-core over its DevTools
// protocol.
//
//   node tests/browser/instructor_page.mjs URL [STATION]
//
// URL: the page's URL as the launcher printed it (with its token). Checks,
// printing one line each and a JSON summary last; exits 1 at the first that
// fails:
//   1. the page loads, the operator's view and a chosen station's view load;
//   2. the chosen station's image changes as the arm moves (two images
//      several frames apart differ);
//   3. Freeze freezes the session (the DCP's frame stops, and the event
//      list shows the command), Run runs it again (the frame moves on);
//   4. Reset sends the session back to Mode 1 (the event list shows the
//      command and the reset), and the autopilot begins again;
//   5. a second viewer joining late sees the events from the session's
//      start, the freeze and the reset included;
//   6. a malfunction injected from the page's menu stops that joint in the
//      DCP's telemetry (the joint the autopilot is moving most, chosen as
//      it flies), the operator station's autopilot reports it (its report is
//      in the event list), and the page's Repair puts it right; a lost
//      camera station's view goes black but for "NO VIDEO".
import {launchChromium, pageErrors, reporter, sleep} from "./chromium.mjs";

const url = process.argv[2];
const station = process.argv[3] || "1";
if (!url) {
  console.error("usage: node instructor_page.mjs URL [STATION]");
  process.exit(2);
}
const result = {};
const {fail, until} = reporter(result);



// The displayed image's pixels, hashed, and the frame it showed.
async function viewPixels(page, id) {
  return page.evaluate((id) => {
    const img = document.getElementById(id);
    if (!img.complete || !img.naturalWidth) return null;
    const c = document.createElement("canvas");
    c.width = img.naturalWidth;
    c.height = img.naturalHeight;
    const g = c.getContext("2d");
    g.drawImage(img, 0, 0);
    const d = g.getImageData(0, 0, c.width, c.height).data;
    let h = 2166136261 >>> 0, lit = 0;
    for (let i = 0; i < d.length; i += 4) {
      h = Math.imul(h ^ (d[i] + 3 * d[i + 1] + 7 * d[i + 2]), 16777619) >>> 0;
      if (d[i] + d[i + 1] + d[i + 2] > 60) ++lit;
    }
    return {hash: h, lit, width: c.width, loads: Number(img.dataset.loads || 0)};
  }, id);
}

async function dcpFrame(page) {
  return page.evaluate(async () => {
    const token = new URLSearchParams(location.search).get("token");
    const r = await fetch("/api/status?token=" + token, {cache: "no-store"});
    const s = await r.json();
    return s.dcp ? s.dcp.frame : null;
  });
}

const eventsText = (page) => page.evaluate(() => document.getElementById("events").innerText);

const browser = await launchChromium();
try {
  const page = await browser.newPage();
  const errors = pageErrors(page);
  await page.goto(url, {waitUntil: "load", timeout: 30000});
  // 1. The views load.
  await until("the operator's view loads", async () => ((await viewPixels(page, "view0")) || {}).loads >= 2, 30);
  await page.select("#station", station);
  await sleep(500);  // the image asked for before the change may still arrive
  const first = await until("station " + station + "'s view loads", async () => {
    const v = await viewPixels(page, "view1");
    return v && v.loads >= 2 ? v : null;
  }, 30);
  result.view_width = first.width;
  result.lit_pixels = first.lit;
  if (first.lit < 100) fail("station " + station + "'s view is black (" + first.lit + " lit pixels)");
  console.log("ok the page loads; station " + station + "'s view " + first.width + " px wide, " + first.lit + " lit pixels");
  // 2. It changes as the arm moves.
  const f0 = await dcpFrame(page);
  const moved = await until("station " + station + "'s image changes as the arm moves", async () => {
    const v = await viewPixels(page, "view1");
    return v && v.hash !== first.hash ? v : null;
  }, 20);
  result.view_changed_after_frames = (await dcpFrame(page)) - f0;
  console.log("ok station " + station + "'s image changed (" + moved.loads + " images loaded)");
  // 3. Freeze, then run.
  const bannerText = () => page.$eval("#banner", (e) => e.textContent);
  await until("the banner says RUNNING", async () => (await bannerText()) === "RUNNING", 20);
  await page.click("#freeze");
  await until("the freeze is in the event list", async () => /freeze \(from instructor_station\)/.test(await eventsText(page)), 10);
  await until("the freeze answered done", async () =>
      /freeze: DONE, operator_station: frozen at operator frame/.test(await page.$eval("#said", (e) => e.textContent)), 10);
  result.frozen_banner = await until("the banner says FROZEN since", async () => {
    const t = await bannerText();
    return /^FROZEN since .* \(t [0-9.]+ s\)$/.test(t) ? t : null;
  }, 10);
  console.log("ok the banner: " + result.frozen_banner);
  await sleep(700);  // frames in flight through the pipeline
  const a = await dcpFrame(page);
  await sleep(1500);
  const b = await dcpFrame(page);
  result.frozen_frames = [a, b];
  if (a === null || a !== b) fail("frozen, the DCP's frame still moves (" + a + " -> " + b + ")");
  console.log("ok frozen: the DCP's frame holds at " + a);
  // A checkpoint over an existing name is refused by the DCP, and said so.
  const cp = "page-" + Date.now();
  const said = () => page.$eval("#said", (e) => [e.dataset.state, e.textContent]);
  for (let i = 0; i < 2; ++i) {
    await page.$eval("#cpname", (e) => { e.value = ""; });
    await page.type("#cpname", cp);
    await page.click("#checkpoint");
    const want = i === 0 ? "done" : "refused";
    result["checkpoint_" + i] = await until("the checkpoint " + want, async () => {
      const [st, text] = await said();
      return st === want && text.startsWith("checkpoint " + cp) ? text : null;
    }, 10);
    await sleep(600);  // at most 2 checkpoints a second
  }
  if (!/REFUSED, dynamics_proc: .*exists already/.test(result.checkpoint_1)) fail("the refusal does not say why: " + result.checkpoint_1);
  console.log("ok a checkpoint over an existing name: " + result.checkpoint_1);
  await page.click("#run");
  await until("the session runs again", async () => (await dcpFrame(page)) > b, 10);
  await until("the banner says RUNNING again", async () => (await bannerText()) === "RUNNING", 10);
  console.log("ok run: the DCP's frame moves on, the banner says RUNNING");
  // 4. Reset.
  const modeNow = () => page.evaluate(async () => {
    const token = new URLSearchParams(location.search).get("token");
    const s = await (await fetch("/api/status?token=" + token, {cache: "no-store"})).json();
    return s.dcp ? s.dcp.mode : null;
  });
  await page.click("#reset");
  await until("the reset is in the event list", async () => /reset \(from instructor_station\)/.test(await eventsText(page)) &&
      /RESET: back to Mode 1/.test(await eventsText(page)), 10);
  await until("Mode 1 after the reset", async () => (await modeNow()) === 1, 10);
  console.log("ok reset: back to Mode 1");
  // 5. A second viewer, late.
  const late = await browser.newPage();
  await late.goto(url, {waitUntil: "load", timeout: 30000});
  const seen = await until("a late viewer sees the earlier events", async () => {
    const t = await eventsText(late);
    return /Mode 1/.test(t) && /freeze \(from instructor_station\)/.test(t) && /RESET/.test(t) ? t : null;
  }, 15);
  result.late_viewer_events = seen.split("\n").length;
  console.log("ok a late viewer sees " + result.late_viewer_events + " events from the start, the freeze and the reset among them");
  // 6. Malfunctions from the page (the first viewer's, in front again: a
  // background tab's scripts are throttled).
  await late.close();
  await page.bringToFront();
  const status = () => page.evaluate(async () => {
    const token = new URLSearchParams(location.search).get("token");
    return (await fetch("/api/status?token=" + token, {cache: "no-store"})).json();
  });
  const joint = await until("a joint the autopilot moves", async () => {
    const a = (await status()).dcp;
    await sleep(400);
    const b = (await status()).dcp;
    if (!a || !b || b.mode !== 1) return null;
    let best = 0, j = 0;
    for (let i = 0; i < 6; ++i) {
      const d = Math.abs(b.master_angles_deg[i] - a.master_angles_deg[i]);
      if (d > best) { best = d; j = i + 1; }
    }
    return best > 0.2 ? j : null;
  }, 30);
  await page.select("#mkind", "joint_stuck");
  await page.select("#mtarget", String(joint));
  await page.click("#inject");
  await until("the malfunction is in the event list", async () =>
      new RegExp("MALFUNCTION: joint " + joint + " stuck").test(await eventsText(page)), 10);
  await until("the autopilot reports the joint, by name, not following", async () =>
      new RegExp("operator_station reports [^\\n]*joint " + joint + " [a-z ]+[^\\n]*NOT FOLLOWING").test(await eventsText(page)), 20);
  await until("the joint in red", async () => page.$eval("#joints", (t, j) => t.rows[j].cells[1].className === "bad", joint), 10);
  const s1 = (await status()).dcp;
  await sleep(1500);
  const s2 = (await status()).dcp;
  result.stuck = {joint, slave: [s1.slave_angles_deg[joint - 1], s2.slave_angles_deg[joint - 1]],
                  master: s2.master_angles_deg[joint - 1]};
  if (s1.slave_angles_deg[joint - 1] !== s2.slave_angles_deg[joint - 1] ||
      Math.abs(s2.master_angles_deg[joint - 1] - s2.slave_angles_deg[joint - 1]) < 0.5)
    fail("joint " + joint + " is not stopped in the telemetry: " + JSON.stringify(result.stuck));
  console.log("ok joint " + joint + " stuck from the page: stopped at " + s2.slave_angles_deg[joint - 1].toFixed(2) +
              " deg (commanded " + s2.master_angles_deg[joint - 1].toFixed(2) + "), the autopilot reports it");
  // A camera station lost: its view goes black.
  await page.select("#mkind", "camera_lost");
  await page.select("#mtarget", station);
  await page.click("#inject");
  const dark = await until("station " + station + "'s view goes black", async () => {
    const v = await viewPixels(page, "view1");
    return v && v.lit < first.lit / 10 && v.lit > 0 ? v : null;
  }, 20);
  result.lost_lit_pixels = dark.lit;
  console.log("ok camera " + station + " lost: its view shows " + dark.lit + " lit pixels (NO VIDEO)");
  await until("both malfunctions listed with Repair all", async () => (await page.$("#repairall")) !== null, 10);
  await page.click("#repairall");
  await until("the repair is in the event list", async () =>
      new RegExp("repaired: joint " + joint + " stuck").test(await eventsText(page)), 10);
  await until("the joint follows again", async () => {
    const d = (await status()).dcp;
    return d && Math.abs(d.master_angles_deg[joint - 1] - d.slave_angles_deg[joint - 1]) < 0.05;
  }, 10);
  await until("station " + station + "'s view comes back", async () => {
    const v = await viewPixels(page, "view1");
    return v && v.lit > first.lit / 4 ? v : null;
  }, 20);
  console.log("ok repaired from the page: the joint follows and the view is back");
  // 7. A lesson loaded from a file on the page (docs/lessons.md "From the
  // instructor's station"): a bad one refused naming its key, a good one
  // listed and fired (at_s 0: at once, as its time has passed).
  const fs = await import("node:fs");
  const os = await import("node:os");
  const path = await import("node:path");
  const dir = fs.mkdtempSync(path.join(os.tmpdir(), "rmslab-lesson-"));
  const badLesson = path.join(dir, "bad.toml"), goodLesson = path.join(dir, "lesson.toml");
  fs.writeFileSync(badLesson, "[[events]]\nat_s = 0\ndo = \"malfunction joint 9 stuck\"\n");
  // The second event waits for its condition: the payload within 40 ft of
  // the CAE's port (Mode 3).
  fs.writeFileSync(goodLesson, "[[events]]\nat_s = 0\ndo = \"malfunction camera 7 lost\"\n\n" +
                   "[[events]]\nwhen = \"dock_distance_ft < 40\"\ndo = \"malfunction camera 6 lost\"\n");
  await (await page.$("#lessonfile")).uploadFile(badLesson);
  await until("a bad lesson refused naming its key", async () =>
      /refused: .*events\[0\]\.do/.test(await page.$eval("#lessonsaid", (e) => e.textContent)), 10);
  await (await page.$("#lessonfile")).uploadFile(goodLesson);
  await until("the lesson's event listed as fired", async () =>
      /camera 7 lost.*fired at/.test(await page.$eval("#lesson", (e) => e.innerText)), 20);
  await until("the DCP took it", async () => ((await status()).malfunctions || []).includes("camera 7 lost"), 10);
  fs.rmSync(dir, {recursive: true});
  console.log("ok a lesson loaded on the page: a bad one refused naming its key, a good one fired");
  const cond = await until("the lesson's conditional event fires at its condition", async () => {
    const s = await status();
    return (s.malfunctions || []).includes("camera 6 lost") && s.dcp ? s.dcp : null;
  }, 120);
  result.conditional = {mode: cond.mode, dock_distance_ft: cond.dock_distance_ft};
  if (cond.mode !== 3 || !(cond.dock_distance_ft < 40)) fail("the conditional event fired outside its condition: " + JSON.stringify(result.conditional));
  console.log("ok the lesson's conditional malfunction fired in Mode 3, " + cond.dock_distance_ft.toFixed(1) + " ft from the port");
  // The page's audit, live.
  const {createRequire} = await import("node:module");
  await page.evaluate(fs.readFileSync(createRequire(import.meta.url).resolve("axe-core/axe.min.js"), "utf8"));
  const axe = await page.evaluate(async () => (await window.axe.run()).violations.map((v) => ({id: v.id, impact: v.impact})));
  result.axe = axe;
  const serious = axe.filter((v) => v.impact === "serious" || v.impact === "critical");
  if (serious.length) fail("axe-core, live: " + serious.map((v) => v.id + " (" + v.impact + ")").join(", "));
  console.log("ok axe-core, live: no serious or critical violation");
  // 8. Text from the session's messages is shown as text, never run.
  const forged = await page.evaluate(() => ({
    element: document.getElementById("forged") !== null,
    title: document.title,
    shown: document.getElementById("procs").textContent.includes("<img id=forged"),
  }));
  result.forged = forged;
  if (forged.element || forged.title === "pwned") fail("a forged process name became markup");
  if (forged.shown) console.log("ok a forged process name is shown as text");
  // The session's end: the banner says so, with how, and stays.
  result.ended = await until("the banner says SESSION ENDED", async () => {
    const t = await bannerText();
    return /^SESSION ENDED: DOCKED/.test(t) ? t : null;
  }, 150);
  console.log("ok the banner: " + result.ended);
  if (errors.length) fail("the page's scripts failed: " + errors.join("; "));
  result.ok = true;
  console.log(JSON.stringify(result));
} finally {
  await browser.close();
}

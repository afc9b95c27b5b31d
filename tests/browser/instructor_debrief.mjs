// The instructor's page over a recorded session (docs/instructor.md
// "Debrief", "Layout"), in Debian's Chromium through puppeteer-core:
//
//   node tests/browser/instructor_debrief.mjs URL SHOTS_DIR
//
// URL: the page's URL as `scripts/lab debrief` printed it. Checks, one line
// each and a JSON summary last; exits 1 at the first that fails:
//   1. the banner says DEBRIEF, with how the session ended; the controls
//      are disabled;
//   2. at 1280x800 nothing scrolls and the banner, both views, the joints'
//      last row (the finger), the plot and the map are in view; a
//      screenshot is written;
//   3. axe-core finds no serious or critical violation;
//   4. scrubbed to an early time, both views show that frame (the frame
//      each image came from, X-Rmslab-Frame, is the one asked for) and the
//      station's image differs from the one at a late time; the events after
//      the cursor are dimmed; the page gives the command that starts a
//      session from that instant (scripts/lab demo --from SESSION@fFRAME);
//   5. a mark placed at the cursor with a note is listed among the events
//      at its time (and kept by the station in the session's folder);
//   6. at 390x844 (a phone) nothing is wider than the screen and the
//      smallest text is 12 px or more; a screenshot is written.
import {createRequire} from "node:module";
import {readFileSync} from "node:fs";
import {launchChromium, pageErrors, reporter, sleep} from "./chromium.mjs";

const url = process.argv[2], shots = process.argv[3];
if (!url || !shots) {
  console.error("usage: node instructor_debrief.mjs URL SHOTS_DIR");
  process.exit(2);
}
const axeSource = readFileSync(createRequire(import.meta.url).resolve("axe-core/axe.min.js"), "utf8");
const result = {};
const {fail, until} = reporter(result);

// What is on screen at this size: the page's scroll extent and each key
// element's box.
async function layout(page) {
  return page.evaluate(() => {
    const box = (sel) => {
      const e = document.querySelector(sel);
      if (!e) return null;
      const r = e.getBoundingClientRect();
      return {top: r.top, bottom: r.bottom, left: r.left, right: r.right, height: r.height};
    };
    let smallest = 100;
    for (const e of document.querySelectorAll("body *")) {
      if (!e.childNodes.length || ![...e.childNodes].some((n) => n.nodeType === 3 && n.textContent.trim())) continue;
      const r = e.getBoundingClientRect();
      if (!r.width || !r.height) continue;
      smallest = Math.min(smallest, parseFloat(getComputedStyle(e).fontSize));
    }
    return {scrollWidth: document.documentElement.scrollWidth, scrollHeight: document.documentElement.scrollHeight,
            width: innerWidth, height: innerHeight, smallestFontPx: smallest,
            banner: box("#banner"), view0: box("#view0"), view1: box("#view1"), finger: box("#fingerrow"),
            plot: box("#plot"), map: box("#map"), freeze: box("#freeze")};
  });
}
const inView = (b, l) => b && b.top >= 0 && b.bottom <= l.height + 0.5 && b.left >= 0 && b.right <= l.width + 0.5;

const browser = await launchChromium();
try {
  const page = await browser.newPage();
  const errors = pageErrors(page);
  await page.setViewport({width: 1280, height: 800});
  await page.goto(url, {waitUntil: "load", timeout: 30000});
  // 1. The banner.
  const banner = await until("the banner says DEBRIEF", async () => {
    const t = await page.$eval("#banner", (e) => e.textContent);
    return /^DEBRIEF/.test(t) ? t : null;
  }, 20);
  result.banner = banner;
  if (!(await page.$eval("#freeze", (e) => e.disabled))) fail("the controls are enabled in a debrief");
  console.log("ok the banner: " + banner);
  // 2. The layout at 1280x800.
  await until("both views drawn", async () => page.evaluate(() =>
      Number(document.getElementById("view0").dataset.loads || 0) > 0 && Number(document.getElementById("view1").dataset.loads || 0) > 0), 30);
  await until("the joints listed", async () => (await page.$("#fingerrow")) !== null, 10);
  const big = await layout(page);
  result.layout_1280 = big;
  await page.screenshot({path: shots + "/instructor-1280x800.png"});
  if (big.scrollHeight > big.height || big.scrollWidth > big.width)
    fail("the page scrolls at 1280x800: " + big.scrollWidth + "x" + big.scrollHeight);
  for (const k of ["banner", "view0", "view1", "finger", "plot", "map", "freeze"])
    if (!inView(big[k], big)) fail(k + " is not in view at 1280x800: " + JSON.stringify(big[k]));
  await page.screenshot({path: shots + "/instructor-1280x800.png"});
  console.log("ok 1280x800: nothing scrolls; the banner, both views, the finger's row, the plot and the map in view");
  // 3. Accessibility.
  await page.evaluate(axeSource);
  const axe = await page.evaluate(async () => (await window.axe.run()).violations.map(
      (v) => ({id: v.id, impact: v.impact, nodes: v.nodes.length})));
  result.axe = axe;
  const serious = axe.filter((v) => v.impact === "serious" || v.impact === "critical");
  if (serious.length) fail("axe-core: " + serious.map((v) => v.id + " (" + v.impact + ")").join(", "));
  console.log("ok axe-core: no serious or critical violation (" + axe.length + " lesser: " +
              (axe.map((v) => v.id + " " + v.impact).join(", ") || "none") + ")");
  // 4. Scrub to an early time, then a late one.
  const range = await page.$eval("#scrub", (e) => [Number(e.min), Number(e.max)]);
  const early = Math.round(range[0] + (range[1] - range[0]) * 0.1), late = Math.round(range[0] + (range[1] - range[0]) * 0.9);
  const scrubTo = (f) => page.$eval("#scrub", (e, f) => { e.value = String(f); e.dispatchEvent(new Event("input")); }, f);
  const pixels = (id) => page.evaluate((id) => {
    const img = document.getElementById(id), c = document.createElement("canvas");
    if (!img.complete || !img.naturalWidth) return {hash: 0, frame: -1};  // between two images
    c.width = img.naturalWidth; c.height = img.naturalHeight;
    const g = c.getContext("2d"); g.drawImage(img, 0, 0);
    const d = g.getImageData(0, 0, c.width, c.height).data;
    let h = 2166136261 >>> 0;
    for (let i = 0; i < d.length; i += 4) h = Math.imul(h ^ (d[i] + 3 * d[i + 1] + 7 * d[i + 2]), 16777619) >>> 0;
    return {hash: h, frame: Number(img.dataset.frame)};
  }, id);
  const shows = async (f) => {
    await scrubTo(f);
    return until("both views show frame " + f, async () => {
      const a = await pixels("view0"), b = await pixels("view1");
      return a.frame === f && b.frame === f ? b : null;
    }, 30);
  };
  const atLate = await shows(late);
  const atEarly = await shows(early);
  result.scrub = {early, late, early_hash: atEarly.hash, late_hash: atLate.hash};
  if (atEarly.hash === atLate.hash) fail("the station's view is the same at frames " + early + " and " + late);
  const dimmed = await page.evaluate(() => [...document.querySelectorAll("#events div.after")].length);
  if (!dimmed) fail("no event after the cursor is dimmed");
  const branch = await page.$eval("#branch", (e) => e.textContent);
  if (!branch.includes("scripts/lab demo --from ") || !branch.endsWith("@f" + early))
    fail("no way to start a session from the cursor's instant: '" + branch + "'");
  console.log("ok scrubbed: both views show frame " + early + " (and " + late + ", a different image); " + dimmed + " later events dimmed");
  // 5. A mark at the cursor.
  const note = "debrief mark " + Date.now();
  await page.type("#marktext", note);
  await page.click("#mark");
  await until("the mark is among the events", async () =>
      (await page.$eval("#events", (e) => e.innerText)).includes(note), 10);
  const marks = await page.evaluate(async () => {
    const token = new URLSearchParams(location.search).get("token");
    return (await fetch("/api/marks?token=" + token)).json();
  });
  const mine = marks.find((m) => m.text === note);
  if (!mine || Math.abs(mine.session_s - early / 30) > 1) fail("the mark is not at the cursor's time: " + JSON.stringify(marks));
  result.mark = mine;
  console.log("ok a mark at " + mine.session_s.toFixed(1) + " s: " + note);
  // ... but none after the session's end, nor at a time written otherwise than in decimals.
  const beyond = await page.evaluate(async (t) => {
    const token = new URLSearchParams(location.search).get("token");
    const post = async (v) => (await fetch("/api/mark?token=" + token, {method: "POST",
      headers: {"Content-Type": "application/x-www-form-urlencoded"}, body: "text=late&t=" + v})).status;
    return [await post(String(t)), await post("0x10")];
  }, range[1] / 30 + 0.2);
  if (beyond[0] !== 400 || beyond[1] !== 400) fail("a mark after the end or at t=0x10 was taken: " + beyond);
  const title = await page.$eval("#scoretitle", (e) => e.textContent);
  if (!/session's/.test(title)) fail("the debrief's scorecard says '" + title + "'");
  // 6. A phone.
  await page.setViewport({width: 390, height: 844, isMobile: true, hasTouch: true});
  await sleep(800);
  const phone = await layout(page);
  result.layout_390 = phone;
  await page.screenshot({path: shots + "/instructor-390x844.png", fullPage: true});
  if (phone.scrollWidth > phone.width + 0.5) fail("the page is wider than a 390 px phone: " + phone.scrollWidth);
  if (phone.smallestFontPx < 12) fail("text of " + phone.smallestFontPx + " px on a phone");
  if (!phone.freeze || phone.freeze.right > 390.5) fail("the controls are off-screen on a phone: " + JSON.stringify(phone.freeze));
  console.log("ok 390x844: nothing wider than the screen, the smallest text " + phone.smallestFontPx + " px");
  // Scrubbing on a phone keeps the page where it is (only the events list scrolls).
  await page.evaluate(() => window.scrollTo(0, 0));
  await scrubTo(late);
  await sleep(800);
  await scrubTo(early);
  await sleep(800);
  const scrolled = await page.evaluate(() => window.scrollY);
  if (scrolled > 5) fail("scrubbing on a phone scrolled the page " + scrolled + " px away from the views");
  console.log("ok scrubbing on a phone leaves the page where it was");
  if (errors.length) fail("the page's scripts failed: " + errors.join("; "));
  result.ok = true;
  console.log(JSON.stringify(result));
} finally {
  await browser.close();
}

// A picture of the instructor's page for the docs (docs/images/instructor.png):
//   node tests/browser/screenshot.mjs URL OUT.png [STATION] [AT_SESSION_S]
// Opens the page in the system's Chromium (puppeteer-core), picks STATION
// (default 7), waits until the session's time passes AT_SESSION_S (default
// 0) and both views have loaded, and saves a screenshot of the page.
import {launchChromium} from "./chromium.mjs";

const [url, out, station = "7", at = "0"] = process.argv.slice(2);
if (!url || !out) {
  console.error("usage: node screenshot.mjs URL OUT.png [STATION] [AT_SESSION_S]");
  process.exit(2);
}
const browser = await launchChromium({
  defaultViewport: {width: 1600, height: 1000},
});
try {
  const page = await browser.newPage();
  await page.goto(url, {waitUntil: "load", timeout: 30000});
  await page.waitForSelector("#station option");
  await page.select("#station", station);
  await page.waitForFunction(
      (at) => {
        const t = document.getElementById("clock").textContent.match(/t ([\d.]+) s/);
        const loaded = ["view0", "view1"].every((id) => Number(document.getElementById(id).dataset.loads || 0) >= 3);
        return t && Number(t[1]) >= at && loaded;
      },
      {timeout: 300000, polling: 250}, Number(at));
  await new Promise((r) => setTimeout(r, 600));
  await page.screenshot({path: out});
  console.log("wrote " + out);
} finally {
  await browser.close();
}

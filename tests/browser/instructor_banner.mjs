// What the instructor's page's banner says, in Debian's Chromium
// (docs/instructor.md "The banner"):
//
//   node tests/browser/instructor_banner.mjs URL PATTERN [SECONDS]
//
// Loads the page and waits (default 20 s) until the banner and the note
// beside it, as one line ("RUNNING | STATION RESTARTED: ..."), match the
// regular expression PATTERN. Prints the line; exits 0 when it matched, 1
// when it did not in time or the page's scripts failed.
import {launchChromium, pageErrors} from "./chromium.mjs";

const [url, pattern, seconds = "20"] = process.argv.slice(2);
if (!url || !pattern) {
  console.error("usage: node instructor_banner.mjs URL PATTERN [SECONDS]");
  process.exit(2);
}
const want = new RegExp(pattern);
const browser = await launchChromium();
let rc = 1;
try {
  const page = await browser.newPage();
  const errors = pageErrors(page);
  await page.setViewport({width: 1280, height: 800});
  await page.goto(url, {waitUntil: "load", timeout: 30000});
  const end = Date.now() + Number(seconds) * 1000;
  let line = "";
  while (Date.now() < end) {
    line = await page.evaluate(() => document.getElementById("banner").textContent + " | " +
                                     document.getElementById("note").textContent);
    if (want.test(line)) break;
    await new Promise((r) => setTimeout(r, 200));
  }
  if (errors.length) console.log("FAIL the page's scripts failed: " + errors.join("; "));
  else if (!want.test(line)) console.log("FAIL the banner says '" + line + "', not /" + pattern + "/");
  else {
    console.log("ok the banner: " + line);
    rc = 0;
  }
} finally {
  await browser.close();
}
process.exit(rc);

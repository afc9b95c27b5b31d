// The system's Chromium through puppeteer-core, as every browser test and
// script here starts it (RMSLAB_CHROMIUM, else /usr/bin/chromium; headless,
// no sandbox: the tests run as root in a container).
import puppeteer from "puppeteer-core";

export function launchChromium(options = {}) {
  return puppeteer.launch({
    executablePath: process.env.RMSLAB_CHROMIUM || "/usr/bin/chromium",
    headless: true,
    args: ["--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage"],
    ...options,
  });
}

// The page's script errors (and, with consoleErrors, its console's errors),
// collected as they come.
export function pageErrors(page, {consoleErrors = false} = {}) {
  const errors = [];
  page.on("pageerror", (e) => errors.push(String(e)));
  if (consoleErrors) page.on("console", (m) => { if (m.type() === "error") errors.push(m.text()); });
  return errors;
}

export const sleep = (ms) => new Promise((r) => setTimeout(r, ms));

// A browser test's way out: fail(why) prints "FAIL why" and what the test
// had measured (result, as JSON) and exits 1; until(what, fn, seconds)
// polls fn every 0.2 s until it gives a truthy value, else fails naming what.
export function reporter(result) {
  const fail = (why) => {
    console.log("FAIL " + why);
    console.log(JSON.stringify(result));
    process.exit(1);
  };
  const until = async (what, fn, seconds) => {
    const end = Date.now() + seconds * 1000;
    for (;;) {
      const v = await fn();
      if (v) return v;
      if (Date.now() > end) fail(what + " (not within " + seconds + " s)");
      await sleep(200);
    }
  };
  return {fail, until};
}

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

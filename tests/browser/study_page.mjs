// A study's page (scripts/lab study report: study.html, docs/studies.md "The
// report") in a real browser: Debian's headless Chromium driven by
// puppeteer-core, the page checked by axe-core.
//
//   node tests/browser/study_page.mjs FILE CONDITIONS SUBJECTS
//
// Checks, one line each and a JSON summary last; exits 1 at the first that
// fails: the page loads with no script error; its table has a row a
// condition; it has a learning curve a subject, each with its trials
// marked; the conditions compared are listed and the method named; and
// axe-core finds no accessibility violation at all.
import {readFileSync} from "node:fs";
import {createRequire} from "node:module";
import {launchChromium, pageErrors, reporter} from "./chromium.mjs";

const [file, conditions, subjects] = process.argv.slice(2);
if (!file || !conditions || !subjects) {
  console.error("usage: node study_page.mjs FILE CONDITIONS SUBJECTS");
  process.exit(2);
}
const result = {};
const {fail} = reporter(result);
const axeSource = readFileSync(createRequire(import.meta.url).resolve("axe-core/axe.min.js"), "utf8");

const browser = await launchChromium();
try {
  const page = await browser.newPage();
  const errors = pageErrors(page, {consoleErrors: true});
  await page.goto("file://" + file, {waitUntil: "load", timeout: 30000});
  result.title = await page.title();
  result.rows = await page.$$eval("table tbody tr", (r) => r.length);
  if (result.rows !== Number(conditions)) fail(`the table has ${result.rows} rows, not ${conditions}`);
  console.log(`ok: a row a condition (${result.rows})`);
  result.curves = await page.$$eval("svg[role=img]", (s) => s.map((x) => x.querySelectorAll("circle").length));
  if (result.curves.length !== Number(subjects)) fail(`${result.curves.length} learning curves, not ${subjects}`);
  if (result.curves.some((n) => n === 0)) fail("a learning curve has no trial marked");
  console.log(`ok: a learning curve a subject (${result.curves.join(", ")} trials)`);
  const text = await page.evaluate(() => document.body.innerText);
  if (!text.includes("Conditions compared") || !text.includes("statsmodels MixedLM")) fail("no comparison or method");
  result.compared = await page.$$eval("h2 + ul li", (l) => l.length);
  if (result.compared === 0) fail("no comparison listed");
  console.log(`ok: ${result.compared} comparisons, the method named`);
  await page.evaluate(axeSource);
  const axe = await page.evaluate(async () => (await window.axe.run()).violations.map(
      (v) => ({id: v.id, impact: v.impact, nodes: v.nodes.length})));
  result.axe = axe;
  if (axe.length) fail("axe-core: " + axe.map((v) => `${v.id} (${v.impact})`).join(", "));
  console.log("ok: axe-core, no violation");
  if (errors.length) fail("script errors: " + errors.join("; "));
  console.log(JSON.stringify(result));
} finally {
  await browser.close();
}

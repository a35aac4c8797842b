#!/usr/bin/env node
// Headless-Chromium check of surround-calibrate guide --mat's page (tools/calibrate/
// mat_guide_page.cpp) on a generated calibration mat. See README.md here for the set-up.
//
//   node tests/browser/mat_guide.test.mjs URL RIG_WRITTEN TRUE_RIG NOMINAL_RIG [--expect-refusal]
//
// Checks, in order: the page loads and shows the cameras and the top view; the verdict turns
// "pass"; the seam table states its limit and lists every seam under it, in centimetres; every
// camera passed; the page names RIG_WRITTEN as written; in that file every camera's mount is
// within 1 cm and 0.2 degrees of TRUE_RIG's, and it was not so before (NOMINAL_RIG is
// centimetres off): the guide wrote the mounts it solved. With --expect-refusal (a mat declared
// wrong): the verdict turns "fail", the page says nothing was written and names no file, and
// RIG_WRITTEN is still NOMINAL_RIG byte for byte. Exits 0 when all pass, 1 with
// "mat_guide: FAIL: ..." otherwise. Gives up at 120 s.
//
// Environment: CHROMIUM, the browser to drive (default /usr/bin/chromium; guide_test_support.mjs).

import { readFileSync } from "node:fs";
import { Failure, check, logger, runInChromium } from "./guide_test_support.mjs";

const log = logger("mat_guide");

// Each camera's mount of a rig file: {name: {x_m, y_m, z_m, yaw_deg, pitch_deg, roll_deg}}.
// The keys are unique within a camera's entry, whichever style (flow or block) it is written in.
function mounts(file) {
  const text = readFileSync(file, "utf8");
  const entries = text.split(/^\s*- name:\s*/m).slice(1);
  const result = {};
  for (const entry of entries) {
    const name = entry.match(/^([A-Za-z0-9_-]+)/)[1];
    const mount = entry.slice(entry.search(/\bmount:/));
    const value = (key) => Number(mount.match(new RegExp(`\\b${key}:\\s*([-0-9.e+]+)`))[1]);
    result[name] = Object.fromEntries(
        ["x_m", "y_m", "z_m", "yaw_deg", "pitch_deg", "roll_deg"].map((k) => [k, value(k)]));
  }
  return result;
}

// Largest position (cm) and angle (degrees) difference between two mounts.
function difference(a, b) {
  const cm = 100 * Math.hypot(a.x_m - b.x_m, a.y_m - b.y_m, a.z_m - b.z_m);
  const deg = Math.max(...["yaw_deg", "pitch_deg", "roll_deg"].map((k) => {
    const d = Math.abs(a[k] - b[k]) % 360;
    return Math.min(d, 360 - d);
  }));
  return { cm, deg };
}

async function run(url, rigFile, trueRig, nominalRig, expectRefusal, browser) {
  const page = await browser.newPage({ viewport: { width: 1500, height: 900 } });
  const pageErrors = [];
  page.on("pageerror", (error) => pageErrors.push(error.message));

  await page.goto(url, { waitUntil: "domcontentloaded", timeout: 10000 });
  await page.waitForFunction(() => document.getElementById("live").naturalWidth > 0, null,
                             { timeout: 20000 })
      .catch(() => { throw new Failure("#live showed no picture from /stream.mjpg within 20 s"); });
  log("page loaded, the cameras are shown");

  await page.waitForFunction(() => document.getElementById("verdict").dataset.state !== "none",
                             null, { timeout: 90000, polling: 200 })
      .catch(() => { throw new Failure("no verdict within 90 s"); });
  const shown = await page.evaluate(() => ({
    verdict: document.getElementById("verdict").dataset.state,
    verdictText: document.getElementById("verdict").textContent,
    limit: document.getElementById("seam-limit").textContent,
    seams: Array.from(document.querySelectorAll("#seams tbody tr"),
                      (tr) => ({ passed: tr.dataset.passed,
                                 cells: Array.from(tr.cells, (td) => td.textContent) })),
    cameras: Array.from(document.querySelectorAll("#cameras tbody tr"),
                        (tr) => ({ passed: tr.dataset.passed,
                                   cells: Array.from(tr.cells, (td) => td.textContent) })),
    hints: Array.from(document.querySelectorAll("#hints li"), (li) => li.textContent),
    error: document.getElementById("error").textContent,
  }));
  if (expectRefusal) {
    check(shown.verdict === "fail", `the verdict is ${shown.verdict}, not fail: ${shown.verdictText}`);
    check(/nothing was written/.test(shown.error), `the page does not say that nothing was written: '${shown.error}'`);
    const written = await page.innerText("#written");
    check(written === "", `the page names files written: ${written}`);
    check(readFileSync(rigFile, "utf8") === readFileSync(nominalRig, "utf8"), `${rigFile} was changed`);
    check(pageErrors.length === 0, `the page reported errors: ${pageErrors.join("; ")}`);
    log(`refused: ${shown.verdictText}; ${shown.error}; hints: ${shown.hints.slice(0, 2).join(" | ")}`);
    return;
  }
  check(shown.verdict === "pass",
        `the verdict is ${shown.verdict}: ${shown.verdictText}; ${shown.error}; ${shown.hints.join(" | ")}`);
  log(`verdict: ${shown.verdictText}`);

  const limitMatch = shown.limit.match(/limit ([0-9.]+) cm/);
  check(limitMatch, `the seam table states no limit: '${shown.limit}'`);
  const limit = Number(limitMatch[1]);
  check(shown.seams.length === 4, `${shown.seams.length} seams listed, 4 expected`);
  for (const seam of shown.seams) {
    const [cameras, board, rmsCm, maxCm, verdict] = seam.cells;
    check(seam.passed === "true" && verdict === "pass" && Number(rmsCm) < limit,
          `seam ${cameras} on ${board}: RMS ${rmsCm} cm (limit ${limit} cm), ${verdict}`);
    log(`seam ${cameras} on ${board}: RMS ${rmsCm} cm, max ${maxCm} cm (limit ${limit} cm): ${verdict}`);
  }
  check(shown.cameras.length === 4 && shown.cameras.every((c) => c.passed === "true"),
        `not every camera passed: ${JSON.stringify(shown.cameras)}`);

  await page.waitForFunction((file) => document.getElementById("written").textContent.includes(file),
                             rigFile, { timeout: 5000 })
      .catch(() => { throw new Failure(`the page does not name ${rigFile} as written`); });

  const written = mounts(rigFile), truth = mounts(trueRig), nominal = mounts(nominalRig);
  check(Object.keys(truth).length === 4, `${trueRig}: ${Object.keys(truth).length} cameras`);
  for (const name of Object.keys(truth)) {
    check(written[name], `${rigFile} has no camera ${name}`);
    const was = difference(nominal[name], truth[name]);
    const now = difference(written[name], truth[name]);
    check(was.cm > 3, `the nominal mount of ${name} is only ${was.cm.toFixed(2)} cm off the truth`);
    check(now.cm < 1 && now.deg < 0.2,
          `${name}: the mount written is ${now.cm.toFixed(2)} cm and ${now.deg.toFixed(3)} deg off the truth`);
    log(`${name}: written mount ${now.cm.toFixed(2)} cm, ${now.deg.toFixed(3)} deg off the truth ` +
        `(the rig had it ${was.cm.toFixed(1)} cm, ${was.deg.toFixed(1)} deg off)`);
  }
  check(pageErrors.length === 0, `the page reported errors: ${pageErrors.join("; ")}`);
}

const [url, rigFile, trueRig, nominalRig, flag] = process.argv.slice(2);
if (!url || !rigFile || !trueRig || !nominalRig || (flag && flag !== "--expect-refusal")) {
  console.error("usage: node mat_guide.test.mjs URL RIG_WRITTEN TRUE_RIG NOMINAL_RIG [--expect-refusal]");
  process.exit(2);
}
await runInChromium("mat_guide", 120, (browser) =>
  run(url, rigFile, trueRig, nominalRig, flag === "--expect-refusal", browser));

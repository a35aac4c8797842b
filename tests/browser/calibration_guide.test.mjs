#!/usr/bin/env node
// Headless-Chromium check of surround-calibrate guide's page (tools/calibrate/guide_page.cpp)
// while it replays a generated calibration session. See README.md here for the set-up.
//
//   node tests/browser/calibration_guide.test.mjs URL LENS_FILE TRUE_RIG
//
// Checks, in order: the page loads and shows the camera; hints name the parts of the picture
// still missing while views are being kept; the list of kept views grows and the coverage map
// fills; the verdict turns "pass" and the page names the lens file written; that file is a lens
// block whose focal length and principal point are those of TRUE_RIG's camera (0.5 %, 1 px).
// Exits 0 when all pass, 1 with "calibration_guide: FAIL: ..." otherwise. Gives up at 90 s.
//
// Environment: CHROMIUM, the browser to drive (default /usr/bin/chromium).

import { readFileSync } from "node:fs";
import { Failure, check, logger, runInChromium } from "./guide_test_support.mjs";

const log = logger("calibration_guide");

// One number of a YAML line "key: value" (the lens block is flat).
function yamlNumber(text, key) {
  const match = text.match(new RegExp(`^\\s*${key}:\\s*([-0-9.e+]+)`, "m"));
  return match ? Number(match[1]) : NaN;
}

async function run(url, lensFile, rigFile, browser) {
  const page = await browser.newPage({ viewport: { width: 1400, height: 900 } });
  const pageErrors = [];
  page.on("pageerror", (error) => pageErrors.push(error.message));

  await page.goto(url, { waitUntil: "domcontentloaded", timeout: 10000 });
  await page.waitForFunction(() => document.getElementById("live").naturalWidth > 0, null,
                             { timeout: 10000 })
      .catch(() => { throw new Failure("#live showed no picture from /stream.mjpg within 10 s"); });
  log("page loaded, the camera is shown");

  // Follow the page until it passes: what it showed on the way.
  const seen = { hints: new Set(), views: new Set(), covered: new Set() };
  const deadline = Date.now() + 60000;
  for (;;) {
    const now = await page.evaluate(() => ({
      verdict: document.getElementById("verdict").dataset.state,
      views: document.querySelectorAll("#views li").length,
      covered: Number(document.getElementById("coverage").dataset.covered),
      hints: Array.from(document.querySelectorAll("#hints li"), (li) => li.textContent),
      phase: document.getElementById("phase").dataset.phase,
    }));
    if (now.verdict !== "pass") now.hints.forEach((h) => seen.hints.add(h));
    seen.views.add(now.views);
    seen.covered.add(now.covered);
    if (now.verdict === "pass") break;
    check(now.phase !== "ended", "the recording ended before the verdict was a pass");
    check(Date.now() < deadline, `no pass within 60 s (verdict ${now.verdict}, ${now.views} views)`);
    await page.waitForFunction(
        (before) => document.getElementById("views").children.length !== before.views ||
                    document.getElementById("verdict").dataset.state !== before.verdict,
        now, { timeout: 10000, polling: 100 }).catch(() => {});
  }
  const where = [...seen.hints].filter((h) => /^(tilt the board into|move the board to) the /.test(h));
  check(where.length > 0, `no hint named a part of the picture; hints seen: ${[...seen.hints].join(" | ")}`);
  log(`hints on the way: ${where.join(" | ")}`);
  const viewCounts = [...seen.views].sort((a, b) => a - b);
  check(viewCounts.length >= 2 && viewCounts[viewCounts.length - 1] >= 5,
        `the list of views did not grow to at least 5: saw ${viewCounts.join(", ")}`);
  const shares = [...seen.covered].sort((a, b) => a - b);
  check(shares.length >= 2 && shares[shares.length - 1] > shares[0] && shares[shares.length - 1] >= 35,
        `the coverage map did not fill: saw ${shares.join(", ")} %`);
  log(`views kept: ${viewCounts.join(" -> ")}; coverage ${shares.join(" -> ")} %`);

  const verdict = await page.innerText("#verdict");
  await page.waitForFunction((file) => document.getElementById("written").textContent.includes(file),
                             lensFile, { timeout: 5000 })
      .catch(() => { throw new Failure(`the page does not name ${lensFile} as written`); });
  log(`verdict: ${verdict}`);

  const lens = readFileSync(lensFile, "utf8");
  const rig = readFileSync(rigFile, "utf8");
  check(/^lens:/m.test(lens) && /model: fisheye/.test(lens), `${lensFile} is no fisheye lens block`);
  for (const key of ["fx_px", "fy_px"]) {
    const got = yamlNumber(lens, key), want = yamlNumber(rig, key);
    check(Math.abs(got / want - 1) < 0.005, `${key} ${got}, truth ${want}: more than 0.5 % off`);
  }
  for (const key of ["cx_px", "cy_px"]) {
    const got = yamlNumber(lens, key), want = yamlNumber(rig, key);
    check(Math.abs(got - want) < 1, `${key} ${got}, truth ${want}: more than 1 px off`);
  }
  check(pageErrors.length === 0, `the page reported errors: ${pageErrors.join("; ")}`);
  log(`${lensFile}: a fisheye lens block within 0.5 % and 1 px of the truth`);
}

const [url, lensFile, rigFile] = process.argv.slice(2);
if (!url || !lensFile || !rigFile) {
  console.error("usage: node calibration_guide.test.mjs URL LENS_FILE TRUE_RIG");
  process.exit(2);
}
await runInChromium("calibration_guide", 90, (browser) => run(url, lensFile, rigFile, browser));

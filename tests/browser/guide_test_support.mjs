// Shared by the guide pages' browser tests (calibration_guide.test.mjs, mat_guide.test.mjs): a
// failed check, the log line with the time since start, and the run of one check against
// headless Chromium with a time limit, which prints "NAME: PASS" or "NAME: FAIL: why".
//
// Environment: CHROMIUM, the browser to drive (default /usr/bin/chromium).

import { chromium } from "playwright-core";

const startedAt = Date.now();

export class Failure extends Error {}

export function check(condition, message) {
  if (!condition) throw new Failure(message);
}

export function logger(name) {
  return (message) =>
    console.log(`${name}: [${((Date.now() - startedAt) / 1000).toFixed(1)} s] ${message}`);
}

// Runs `body(browser)`; exit status 0 on a pass, 1 on a failure or after `limitS` seconds.
export async function runInChromium(name, limitS, body) {
  const browser = await chromium.launch({
    executablePath: process.env.CHROMIUM || "/usr/bin/chromium",
    headless: true,
    args: ["--disable-dev-shm-usage"],
  });
  const timer = setTimeout(() => {
    console.error(`${name}: FAIL: gave up after ${limitS} s`);
    process.exit(1);
  }, limitS * 1000);
  try {
    await body(browser);
    console.log(`${name}: PASS`);
  } catch (error) {
    console.error(`${name}: FAIL: ${error instanceof Failure ? error.message : error.stack}`);
    process.exitCode = 1;
  } finally {
    clearTimeout(timer);
    await browser.close();
  }
}

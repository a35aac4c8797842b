#!/usr/bin/env node
// Headless-Chromium check of surroundd's live page (render/outputs/http_page.cpp) against a running HTTP
// stream output. See README.md here for how to set it up and run it.
//
//   node tests/browser/live_page.test.mjs URL [--view NAME] [--min-view-change LEVELS]
//
// Checks, in order: the page loads, the stream shows a picture and the status fills from
// /status.json; the picture changes over time (or the status' frame counter does); clicking the
// #view-NAME button (default top) is answered 202, marks the button, and changes the picture by at
// least LEVELS (mean absolute difference of 8-bit channels, default 8). Exits 0 when all pass,
// 1 with "live_page: FAIL: ..." otherwise, 2 for a usage error. Takes about 5 s; gives up at 60 s.
//
// Environment: CHROMIUM, the browser to drive (default /usr/bin/chromium).

import { chromium } from "playwright-core";

const usage = "usage: node live_page.test.mjs URL [--view NAME] [--min-view-change LEVELS]";
const startedAt = Date.now();

function parseArguments(argv) {
  const options = { url: null, view: "top", minViewChange: 8 };
  for (let i = 0; i < argv.length; ++i) {
    if (argv[i] === "--view" && i + 1 < argv.length) options.view = argv[++i];
    else if (argv[i] === "--min-view-change" && i + 1 < argv.length) {
      options.minViewChange = Number(argv[++i]);
    } else if (!argv[i].startsWith("--") && options.url === null) options.url = argv[i];
    else return null;
  }
  return options.url !== null && Number.isFinite(options.minViewChange) ? options : null;
}

class Failure extends Error {}
function check(condition, message) {
  if (!condition) throw new Failure(message);
}
function log(message) {
  console.log(`live_page: [${((Date.now() - startedAt) / 1000).toFixed(1)} s] ${message}`);
}
const sleep = (ms) => new Promise((resolve) => setTimeout(resolve, ms));

// The picture #live shows now, drawn at 160x90 into a canvas: its RGBA bytes. (Same origin, so the
// canvas can be read back; Chromium draws a multipart image's current part.)
function samplePicture(page) {
  return page.evaluate(() => {
    const canvas = document.createElement("canvas");
    canvas.width = 160;
    canvas.height = 90;
    const context = canvas.getContext("2d", { willReadFrequently: true });
    context.drawImage(document.getElementById("live"), 0, 0, canvas.width, canvas.height);
    return Array.from(context.getImageData(0, 0, canvas.width, canvas.height).data);
  });
}

// Mean absolute difference over the R, G and B channels, in 8-bit levels.
function meanAbsoluteDifference(a, b) {
  let sum = 0;
  for (let i = 0; i < a.length; i += 4) {
    sum += Math.abs(a[i] - b[i]) + Math.abs(a[i + 1] - b[i + 1]) + Math.abs(a[i + 2] - b[i + 2]);
  }
  return sum / ((a.length / 4) * 3);
}

async function statusFrames(page) {
  return page.evaluate(async () => {
    const status = await (await fetch("/status.json", { cache: "no-store" })).json();
    return typeof status.frames === "number" ? status.frames : null;
  });
}

async function clickView(page, view) {
  const [response] = await Promise.all([
    page.waitForResponse((r) => r.request().method() === "POST" && r.url().includes("/view?"),
                         { timeout: 5000 }),
    page.click(`#view-${view}`, { timeout: 5000 }),
  ]);
  if (response.status() !== 202) {
    const body = await response.text().catch(() => "");
    throw new Failure(`POST ${response.url()} answered ${response.status()}, expected 202: ${body}`);
  }
  await page.waitForFunction((v) => document.getElementById(`view-${v}`).classList.contains("active"),
                             view, { timeout: 2000 });
}

async function run(options, browser) {
  const page = await browser.newPage({ viewport: { width: 1400, height: 900 } });
  const pageErrors = [];
  page.on("pageerror", (error) => pageErrors.push(error.message));
  page.on("console", (message) => {
    if (message.type() === "error") pageErrors.push(message.text());
  });

  // 1. The page loads, the stream shows a picture, the status fills.
  await page.goto(options.url, { waitUntil: "domcontentloaded", timeout: 10000 });
  await page.waitForSelector("#live", { timeout: 5000 });
  await page.waitForFunction(() => document.getElementById("live").naturalWidth > 0, null,
                             { timeout: 10000 })
      .catch(() => { throw new Failure("#live showed no picture from /stream.mjpg within 10 s"); });
  await page.waitForFunction(() => document.getElementById("status").dataset.state === "ok", null,
                             { timeout: 5000 })
      .catch(() => { throw new Failure("#status was not filled from /status.json within 5 s"); });
  const size = await page.evaluate(() => {
    const live = document.getElementById("live");
    return `${live.naturalWidth}x${live.naturalHeight}`;
  });
  const statusText = (await page.innerText("#status")).replace(/\s+/g, " ").trim();
  check(statusText.length > 0, "#status is empty");
  log(`page loaded: picture ${size}, status "${statusText}"`);

  // 2. The picture is live.
  const first = await samplePicture(page);
  const firstFrames = await statusFrames(page);
  let moved = 0;
  let frames = firstFrames;
  for (let attempt = 0; attempt < 4 && moved === 0 && frames === firstFrames; ++attempt) {
    await sleep(500);
    moved = meanAbsoluteDifference(first, await samplePicture(page));
    frames = await statusFrames(page);
  }
  check(moved > 0 || (firstFrames !== null && frames !== firstFrames),
        "the picture did not change over 2 s (and no frame counter in the status moved)");
  log(`picture is live: changed by ${moved.toFixed(2)} levels, status frames ${firstFrames} -> ${frames}`);

  // 3. A view button switches the picture.
  const views = await page.$$eval("#views button", (buttons) =>
      buttons.map((b) => ({ view: b.dataset.view, active: b.classList.contains("active") })));
  check(views.some((v) => v.view === options.view),
        `no #view-${options.view} button; the page offers [${views.map((v) => v.view).join(", ")}]`);
  if (views.find((v) => v.view === options.view).active) {
    const other = views.find((v) => v.view !== options.view);
    check(other !== undefined, `${options.view} is the only view and already shown`);
    log(`${options.view} is already shown: switching to ${other.view} first`);
    await clickView(page, other.view);
    await sleep(1500);
  }
  const before = await samplePicture(page);
  await clickView(page, options.view);
  let change = 0;
  for (const until = Date.now() + 5000; Date.now() < until && change < options.minViewChange;) {
    await sleep(250);
    change = Math.max(change, meanAbsoluteDifference(before, await samplePicture(page)));
  }
  check(change >= options.minViewChange,
        `after clicking #view-${options.view} the picture changed by only ${change.toFixed(2)} ` +
        `levels within 5 s (need ${options.minViewChange})`);
  log(`#view-${options.view}: 202, marked active, picture changed by ${change.toFixed(2)} levels`);

  check(pageErrors.length === 0, `errors on the page: ${pageErrors.join("; ")}`);
}

const options = parseArguments(process.argv.slice(2));
if (options === null) {
  console.error(usage);
  process.exit(2);
}
setTimeout(() => {
  console.error("live_page: FAIL: gave up after 60 s");
  process.exit(1);
}, 60000);

let browser = null;
let status = 0;
try {
  browser = await chromium.launch({
    executablePath: process.env.CHROMIUM || "/usr/bin/chromium",
    headless: true,
    args: ["--disable-dev-shm-usage"],
  });
  await run(options, browser);
  log("PASS");
} catch (error) {
  console.error(`live_page: FAIL: ${error instanceof Failure ? error.message : error.stack}`);
  status = 1;
} finally {
  if (browser !== null) await browser.close().catch(() => {});
}
process.exit(status);

#include "tools/calibrate/guide/guide_page.hpp"

#include <fmt/format.h>

namespace surroundd::calibrate {

std::string guidePageFrom(std::string_view title, std::string_view style, std::string_view body,
                          std::string_view script) {
  // The frame both pages share: a dark page, a header with #phase, #hints and the verdict in the
  // same colours, and the poll of /state.json that hands each state to the page's show().
  return fmt::format(R"page(<!doctype html>
<html lang="en">
<head>
<meta charset="utf-8">
<meta name="viewport" content="width=device-width, initial-scale=1">
<title>{}</title>
<link rel="icon" href="data:,">
<style>
  :root {{ color-scheme: dark; font-family: system-ui, sans-serif; }}
  body {{ margin: 0; background: #111; color: #ddd; }}
  header {{ display: flex; gap: 1.5em; align-items: center; padding: .4em 1em; background: #222; }}
  h1 {{ font-size: 1.1em; margin: 0; }}
  h2 {{ font-size: 1em; margin: .8em 0 .3em; color: #aaa; }}
  ul {{ margin: 0; padding-left: 1.2em; }}
  #hints li {{ color: #fc6; }}
  #verdict[data-state="pass"] {{ color: #6e6; font-weight: bold; }}
  #verdict[data-state="fail"] {{ color: #f77; }}
  #error {{ color: #f77; }}
  #phase[data-phase="passed"] {{ color: #6e6; }}
{}</style>
</head>
<body>
{}<script>
"use strict";
const $ = (id) => document.getElementById(id);
{}
async function poll() {{
  try {{
    const response = await fetch("state.json", {{ cache: "no-store" }});
    if (response.ok) show(await response.json());
  }} catch (error) {{
    $("phase").textContent = "no answer from surround-calibrate";
  }}
  setTimeout(poll, 300);
}}
poll();
</script>
</body>
</html>
)page",
                     title, style, body, script);
}

std::string_view guidePage() {
  static const std::string kPage = guidePageFrom(
      "surround-calibrate guide",
      R"style(  main { display: grid; grid-template-columns: minmax(0, 3fr) minmax(16em, 1fr); gap: 1em;
         padding: 1em; }
  #live { width: 100%; background: #000; display: block; }
  #coverage { width: 100%; background: #000; display: block; margin-top: .5em; }
  #views li { font-size: .9em; }
)style",
      R"body(<header><h1>Guided calibration</h1><span id="board"></span><span id="phase" data-phase="">
connecting&hellip;</span><span id="progress"></span></header>
<main>
<section>
  <img id="live" src="stream.mjpg" alt="the camera, live">
  <canvas id="coverage" data-covered="0" width="640" height="360"></canvas>
</section>
<aside>
  <h2>Still missing</h2><ul id="hints"></ul>
  <h2>Last frame</h2><div id="last"></div>
  <h2>Verdict</h2><div id="verdict" data-state="none">not solved yet</div><div id="written"></div>
  <div id="error"></div>
  <h2>Views kept</h2><ol id="views"></ol>
</aside>
</main>
)body",
      R"script(const colours = ["#4c8", "#48c", "#c84", "#c4c", "#8c4", "#4cc", "#cc4", "#84c"];

function list(element, items, text) {
  element.replaceChildren(...items.map((item) => {
    const li = document.createElement("li");
    li.textContent = text(item);
    return li;
  }));
}

// The coverage map over the kept views' outlines: covered cells green, empty ones in the lens
// red, outside the lens dark; the share against the share needed below.
function drawCoverage(state) {
  const canvas = $("coverage"), c = canvas.getContext("2d");
  const w = state.image.width, h = state.image.height;
  if (!w || !state.coverage) return;
  canvas.width = 640;
  canvas.height = Math.round(640 * h / w);
  const scale = canvas.width / w, cov = state.coverage;
  const cw = canvas.width / cov.columns, ch = canvas.height / cov.rows;
  c.clearRect(0, 0, canvas.width, canvas.height);
  cov.cells.forEach((count, i) => {
    const x = (i % cov.columns) * cw, y = Math.floor(i / cov.columns) * ch;
    c.fillStyle = count < 0 ? "#111" : count > 0 ? "rgba(40,160,70,0.55)" : "rgba(170,40,40,0.45)";
    c.fillRect(x + 1, y + 1, cw - 2, ch - 2);
  });
  state.views.forEach((view, i) => {
    c.strokeStyle = colours[i % colours.length];
    c.lineWidth = 2;
    c.beginPath();
    view.outline.forEach(([x, y], k) => (k ? c.lineTo : c.moveTo).call(c, x * scale, y * scale));
    c.closePath();
    c.stroke();
  });
  c.fillStyle = "#fff";
  c.font = "16px system-ui";
  c.fillText(`coverage ${(100 * cov.share).toFixed(0)} % (needed ${(100 * cov.needed).toFixed(0)} %)`,
             8, canvas.height - 8);
  canvas.dataset.covered = (100 * cov.share).toFixed(1);
}

function show(state) {
  $("board").textContent = `${state.board}, ${state.model}`;
  const phase = $("phase");
  phase.dataset.phase = state.phase;
  phase.textContent = {collecting: "collecting views", passed: "passed", ended: "the recording ended"}[state.phase];
  $("progress").textContent =
      `${state.views.length} of at least ${state.minViews} views, ${state.frames} frames, ${state.streamTimeS.toFixed(1)} s`;
  list($("hints"), state.hints, (h) => h);
  $("last").textContent = `${state.last.outcome}: ${state.last.note}`;
  list($("views"), state.views,
       (v) => `${v.name} at ${v.timeS.toFixed(1)} s: ${v.corners} corners, edges ${v.edgePx.toFixed(1)} px`);
  const verdict = $("verdict");
  if (state.verdict) {
    const v = state.verdict;
    verdict.dataset.state = v.passed ? "pass" : "fail";
    verdict.textContent = `${v.passed ? "pass" : "fail"}: ${v.views} views, RMS ${v.rmsPx.toFixed(3)} px, ` +
        `fx ${v.fx.toFixed(2)} fy ${v.fy.toFixed(2)} cx ${v.cx.toFixed(2)} cy ${v.cy.toFixed(2)}` +
        (v.failures.length ? ` — ${v.failures.join("; ")}` : "");
  }
  $("written").textContent = state.written.length ? `wrote ${state.written.join(", ")}` : "";
  $("error").textContent = state.error;
  drawCoverage(state);
}

)script");
  return kPage;
}

}  // namespace surroundd::calibrate

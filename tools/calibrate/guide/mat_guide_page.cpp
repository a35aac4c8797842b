#include "tools/calibrate/guide/mat_guide_page.hpp"

#include <string>

#include "tools/calibrate/guide/guide_page.hpp"

namespace surroundd::calibrate {

std::string_view matGuidePage() {
  static const std::string kPage = guidePageFrom(
      "surround-calibrate guide --mat",
      R"style(  main { display: grid; grid-template-columns: minmax(0, 3fr) minmax(22em, 2fr); gap: 1em;
         padding: 1em; }
  #live { width: 100%; background: #000; display: block; }
  table { border-collapse: collapse; font-size: .9em; }
  th, td { padding: .15em .5em; text-align: right; }
  th:first-child, td:first-child { text-align: left; }
  tr[data-passed="true"] td:last-child { color: #6e6; }
  tr[data-passed="false"] td:last-child { color: #f77; }
)style",
      R"body(<header><h1>Guided mat calibration</h1><span id="phase" data-phase="">connecting&hellip;</span>
<span id="progress"></span></header>
<main>
<section><img id="live" src="stream.mjpg" alt="the cameras and the stitched top view"></section>
<aside>
  <h2>Verdict</h2><div id="verdict" data-state="none">not solved yet</div><div id="written"></div>
  <div id="error"></div>
  <h2>Seams <span id="seam-limit"></span></h2>
  <table id="seams"><thead><tr><th>cameras</th><th>board</th><th>RMS cm</th><th>max cm</th>
  <th>verdict</th></tr></thead><tbody></tbody></table>
  <h2>Cameras</h2>
  <table id="cameras"><thead><tr><th>camera</th><th>boards</th><th>corners</th><th>RMS px</th>
  <th>moved cm</th><th>turn deg</th><th>verdict</th></tr></thead><tbody></tbody></table>
  <h2>To do</h2><ul id="hints"></ul>
</aside>
</main>
)body",
      R"script(const fixed = (value, digits) => (value === null ? "-" : value.toFixed(digits));
const verdictText = (passed) => (passed === null ? "-" : passed ? "pass" : "FAIL");

function rows(table, items, cells, passed) {
  table.tBodies[0].replaceChildren(...items.map((item) => {
    const tr = document.createElement("tr");
    tr.dataset.passed = String(passed(item));
    for (const text of cells(item)) {
      const td = document.createElement("td");
      td.textContent = text;
      tr.append(td);
    }
    return tr;
  }));
}

function show(state) {
  const phase = $("phase");
  phase.dataset.phase = state.phase;
  phase.textContent = {waiting: "waiting for the cameras", failed: "failed: fix and wait for the next pictures",
                       passed: "passed", ended: "the pictures ended"}[state.phase];
  $("progress").textContent = `${state.solves} solve${state.solves === 1 ? "" : "s"}`;
  $("seam-limit").textContent = `(limit ${state.seamLimitCm} cm RMS)`;
  rows($("seams"), state.seams,
       (s) => [s.cameras, s.board, s.rmsCm.toFixed(2), s.maxCm.toFixed(2), verdictText(s.passed)],
       (s) => s.passed);
  rows($("cameras"), state.cameras,
       (c) => [c.name, `${c.boardsFound}/${c.boardsExpected}`, String(c.corners), fixed(c.rmsPx, 3),
               fixed(c.movedCm, 1), fixed(c.turnDeg, 2), verdictText(c.passed)],
       (c) => c.passed);
  const list = $("hints");
  list.replaceChildren(...state.hints.map((hint) => {
    const li = document.createElement("li");
    li.textContent = hint;
    return li;
  }));
  const verdict = $("verdict");
  if (state.verdict) {
    verdict.dataset.state = state.verdict.passed ? "pass" : "fail";
    verdict.textContent = state.verdict.passed
        ? `pass: every camera and seam within the limits`
        : `fail: ${state.verdict.failures} problem${state.verdict.failures === 1 ? "" : "s"}; nothing written`;
  }
  $("written").textContent = state.written.length ? `wrote ${state.written.join(", ")}` : "";
  $("error").textContent = state.error;
}

)script");
  return kPage;
}

}  // namespace surroundd::calibrate

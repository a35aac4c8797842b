#include "render/outputs/http_page.hpp"

namespace surroundd::render {

std::string_view livePage() {
  return R"page(<!doctype html>
<html lang="en">
<head>
<meta charset="utf-8">
<meta name="viewport" content="width=device-width, initial-scale=1">
<title>surroundd live</title>
<link rel="icon" href="data:,">
<style>
  :root { color-scheme: dark; font-family: system-ui, sans-serif; }
  body { margin: 0; background: #111; color: #ddd; }
  header, #controls { display: flex; flex-wrap: wrap; gap: .5em 1.5em; align-items: center;
                      padding: .4em 1em; }
  header { background: #222; }
  h1 { font-size: 1.1em; margin: 0; }
  #connection { color: #999; font-size: .9em; }
  #views { display: flex; flex-wrap: wrap; gap: .4em; }
  #views button { font: inherit; padding: .3em .9em; border: 1px solid #555; border-radius: 4px;
                  background: #2a2a2a; color: inherit; cursor: pointer; }
  #views button.active { background: #2d6cdf; border-color: #2d6cdf; color: #fff; }
  #view-error { color: #f77; margin: 0; }
  #status { display: flex; flex-wrap: wrap; gap: .3em 1em; align-items: center; }
  #status[data-state="error"] { color: #f77; }
  #fps { font-size: 1.2em; }
  #cameras { list-style: none; padding: 0; margin: 0; display: flex; gap: .3em; }
  #cameras li { padding: .1em .5em; border-radius: 3px; }
  #cameras li.ok { background: #1f5130; }
  #cameras li.bad { background: #7a2020; }
  dl { display: flex; flex-wrap: wrap; gap: .2em .6em; margin: 0; font-size: .85em; }
  dt { color: #999; }
  dd { margin: 0; overflow-wrap: anywhere; }
  #live { display: block; margin: 0 auto; max-width: 100%; max-height: calc(100vh - 7em);
          background: #000; }
</style>
</head>
<body>
<header><h1>surroundd</h1><span id="connection">connecting&hellip;</span></header>
<section id="controls">
  <nav id="views" aria-label="views" hidden></nav>
  <section id="status" data-state="waiting" data-updates="0" aria-live="polite">
    <span id="fps">waiting for status&hellip;</span>
    <span id="frames"></span>
    <ul id="cameras"></ul>
    <dl id="details"></dl>
  </section>
  <p id="view-error" role="alert"></p>
</section>
<img id="live" src="/stream.mjpg" alt="live surround view">
<script>
"use strict";
const byId = (id) => document.getElementById(id);
const shownElsewhere = new Set(["fps", "frames", "cameras"]);

function element(tag, text, className) {
  const node = document.createElement(tag);
  node.textContent = text;
  if (className) node.className = className;
  return node;
}

// {"front": "ok", ...} or [{"name": "front", "health": "ok"}, ...]
function cameraEntries(cameras) {
  if (Array.isArray(cameras)) return cameras.map((c) => [c.name, c.health ?? c.state]);
  return cameras && typeof cameras === "object" ? Object.entries(cameras) : [];
}

function showStatus(status) {
  byId("fps").textContent = typeof status.fps === "number" ? `${status.fps.toFixed(1)} fps`
      : Object.keys(status).length === 0 ? "no status yet" : "";
  byId("frames").textContent = typeof status.frames === "number" ? `frame ${status.frames}` : "";
  byId("cameras").replaceChildren(...cameraEntries(status.cameras).map(([name, health]) => {
    const item = element("li", `${name} ${health}`, health === "ok" ? "ok" : "bad");
    item.id = `camera-${name}`;
    return item;
  }));
  byId("details").replaceChildren(...Object.entries(status)
      .filter(([key]) => !shownElsewhere.has(key))
      .flatMap(([key, value]) => [element("dt", key),
          element("dd", typeof value === "object" ? JSON.stringify(value) : String(value))]));
}

let updates = 0;
async function refreshStatus() {
  const box = byId("status");
  try {
    const response = await fetch("/status.json", {cache: "no-store"});
    if (!response.ok) throw new Error(`HTTP ${response.status}`);
    showStatus(await response.json());
    // The view may also be switched from elsewhere (surroundctl view).
    markView((await (await fetch("/views.json", {cache: "no-store"})).json()).active);
    box.dataset.state = "ok";
    box.dataset.updates = String(++updates);
    byId("connection").textContent = "live";
  } catch (error) {
    box.dataset.state = "error";
    byId("connection").textContent = `no status (${error.message})`;
  }
}

function markView(active) {
  for (const button of byId("views").querySelectorAll("button")) {
    const on = button.dataset.view === active;
    button.classList.toggle("active", on);
    button.setAttribute("aria-pressed", String(on));
  }
}

async function chooseView(name) {
  const response = await fetch(`/view?name=${encodeURIComponent(name)}`, {method: "POST"});
  if (response.status === 202) {
    markView(name);
    byId("view-error").textContent = "";
  } else {
    byId("view-error").textContent = await response.text();
  }
}

async function loadViews() {
  const {views, active} = await (await fetch("/views.json", {cache: "no-store"})).json();
  const nav = byId("views");
  nav.replaceChildren(...views.map((name) => {
    const button = element("button", name);
    button.type = "button";
    button.id = `view-${name}`;
    button.dataset.view = name;
    button.addEventListener("click", () => chooseView(name));
    return button;
  }));
  nav.hidden = views.length === 0;
  markView(active);
}

// The stream ends when surroundd stops or restarts: try again every 2 s.
byId("live").addEventListener("error", () => {
  byId("connection").textContent = "stream lost, retrying";
  setTimeout(() => { byId("live").src = `/stream.mjpg?t=${Date.now()}`; }, 2000);
});

loadViews().catch((error) => { byId("view-error").textContent = `views: ${error.message}`; });
refreshStatus();
setInterval(refreshStatus, 1000);
</script>
</body>
</html>
)page";
}

}  // namespace surroundd::render

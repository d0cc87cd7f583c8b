// The replay page: asks the server for the trace's meta, all events, the plan trees and the state at the slider's
// time, and draws them with views.js (window.AlicaViews). This file keeps the slider, play and next-event logic.
"use strict";
(function () {
  const $ = (id) => document.getElementById(id);
  const V = window.AlicaViews;
  let meta = null, events = [], trees = null, playing = false, lastFrame = 0, stateAsked = -1;

  async function get(path) {
    const response = await fetch(path, { credentials: "same-origin" });
    if (!response.ok) { throw new Error(path + ": " + response.status); }
    return response.json();
  }

  function now() { return parseFloat($("slider").value); }

  function baseName(path) { const parts = String(path).split(/[\\/]/); return parts[parts.length - 1]; }

  // The field of the whole trace's poses, so that the map keeps its frame while the slider moves.
  function extent() {
    let x0 = Infinity, y0 = Infinity, x1 = -Infinity, y1 = -Infinity;
    for (const e of events) {
      if (e.event === "pose" && typeof e.x === "number" && typeof e.y === "number") {
        x0 = Math.min(x0, e.x); x1 = Math.max(x1, e.x); y0 = Math.min(y0, e.y); y1 = Math.max(y1, e.y);
      }
    }
    return x0 === Infinity ? null : [x0 - 1, y0 - 1, Math.max(x1, x0 + 1) + 1, Math.max(y1, y0 + 1) + 1];
  }

  async function showState() {
    const t = now();
    $("time").textContent = "t = " + t.toFixed(3) + " s";
    stateAsked = t;
    const state = await get("api/state?t=" + t);
    if (stateAsked !== t) { return; }
    V.agents($("agents-body"), state);
    showLog(t);
    V.map($("map-body"), state, V.tracks(events, t), meta);
    if (state.world === "blocks") { V.blocks($("blocks-body"), state, meta); }
    V.trees($("trees-body"), state, trees);
    V.operator($("operator-body"), state);
  }

  function showLog(t) { V.log($("log-body"), events, $("filter").value, t, $("raw").checked); }

  async function jump(kind) {
    const answer = await get("api/next?kind=" + kind + "&after=" + now());
    if (answer.t === null) { $("jump-note").textContent = "no " + kind + " after this time"; return; }
    $("jump-note").textContent = "";
    $("slider").value = answer.t;
    await showState();
  }

  function frame(stamp) {
    if (!playing) { return; }
    const dt = lastFrame ? (stamp - lastFrame) / 1000 : 0;
    lastFrame = stamp;
    const t = Math.min(now() + dt * parseFloat($("speed").value), meta.end);
    $("slider").value = t;
    showState();
    if (t >= meta.end) { setPlaying(false); return; }
    setTimeout(() => requestAnimationFrame(frame), 100);
  }

  function setPlaying(on) {
    playing = on;
    $("play").textContent = on ? "pause" : "play";
    lastFrame = 0;
    if (on) { requestAnimationFrame(frame); }
  }

  async function start() {
    meta = await get("api/meta");
    events = (await get("api/events")).events;
    trees = await get("api/trees");
    meta.extent = extent();
    const file = $("file");
    file.textContent = baseName(meta.file) + " \u2014 " + meta.events + " events, " + meta.duration.toFixed(3) + " s";
    file.title = meta.file;
    $("notes").textContent = [...(meta.notes || []), ...(meta.plan_notes || [])].join(" ");
    $("kinds").textContent = "kinds: " + Object.entries(meta.kinds).map(([k, n]) => k + " (" + n + ")").join(", ");
    const world = (meta.header && meta.header.world) || "none";
    document.body.dataset.world = world;
    $("blocks").hidden = world !== "blocks";
    const slider = $("slider");
    slider.min = meta.start; slider.max = meta.end; slider.value = meta.start;
    slider.addEventListener("input", () => showState());
    $("filter").addEventListener("input", () => showLog(now()));
    $("raw").addEventListener("change", () => showLog(now()));
    $("play").addEventListener("click", () => { if (now() >= meta.end) { slider.value = meta.start; } setPlaying(!playing); });
    $("next-fault").addEventListener("click", () => jump("fault"));
    $("next-replan").addEventListener("click", () => jump("replan"));
    await showState();
    document.body.dataset.ready = "yes";
  }

  start().catch((err) => { document.body.insertAdjacentHTML("afterbegin", '<p class="note">' + err + "</p>"); });
})();

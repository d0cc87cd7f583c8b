// The replay page: asks the server for the trace's meta, all events and the state at the slider's time.
"use strict";
(function () {
  const $ = (id) => document.getElementById(id);
  let meta = null, events = [], playing = false, lastFrame = 0, stateAsked = -1;

  async function get(path) {
    const response = await fetch(path, { credentials: "same-origin" });
    if (!response.ok) { throw new Error(path + ": " + response.status); }
    return response.json();
  }

  function cell(text) { const td = document.createElement("td"); td.textContent = text == null ? "-" : String(text); return td; }

  function fields(e) {
    const rest = {};
    for (const k of Object.keys(e)) { if (k !== "t" && k !== "agent" && k !== "event") { rest[k] = e[k]; } }
    return JSON.stringify(rest);
  }

  function now() { return parseFloat($("slider").value); }

  async function showState() {
    const t = now();
    $("time").textContent = "t = " + t.toFixed(3) + " s";
    stateAsked = t;
    const state = await get("api/state?t=" + t);
    if (stateAsked !== t) { return; }
    const body = $("agents-body");
    body.replaceChildren();
    for (const [name, a] of Object.entries(state.agents)) {
      const tr = document.createElement("tr");
      tr.dataset.agent = name;
      if (!a.alive) { tr.className = "dead"; }
      for (const v of [name, a.role, a.task, a.alive ? "yes" : "no", a.plan, a.state, a.behaviour]) { tr.appendChild(cell(v)); }
      tr.children[4].title = a.plans.map((p) => p.plan + (p.state ? ": " + p.state : "")).join(" \u203a ");
      body.appendChild(tr);
    }
    showLog(t);
    showMap(t);
  }

  function showLog(t) {
    const filter = $("filter").value.trim().toLowerCase();
    const body = $("log-body");
    body.replaceChildren();
    let shown = 0;
    for (const e of events) {
      if (e.t > t) { break; }
      const line = e.event + " " + e.agent + " " + fields(e);
      if (filter && !line.toLowerCase().includes(filter)) { continue; }
      const tr = document.createElement("tr");
      tr.className = "past";
      for (const v of [e.t.toFixed(3), e.agent, e.event, fields(e)]) { tr.appendChild(cell(v)); }
      body.prepend(tr);
      shown += 1;
    }
    body.dataset.shown = String(shown);
  }

  function showMap(t) {
    const box = $("map-body");
    const poses = events.filter((e) => e.event === "pose" && typeof e.x === "number" && typeof e.y === "number");
    if (poses.length === 0) {
      box.innerHTML = '<p class="note">no poses in this trace</p>';
      return;
    }
    let x0 = Infinity, x1 = -Infinity, y0 = Infinity, y1 = -Infinity;
    for (const p of poses) { x0 = Math.min(x0, p.x); x1 = Math.max(x1, p.x); y0 = Math.min(y0, p.y); y1 = Math.max(y1, p.y); }
    const pad = 1, w = Math.max(x1 - x0, 1) + 2 * pad, h = Math.max(y1 - y0, 1) + 2 * pad;
    const paths = {};
    for (const p of poses) { if (p.t <= t) { (paths[p.agent] = paths[p.agent] || []).push(p); } }
    const colours = ["#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#8c564b", "#e377c2", "#17becf"];
    let svg = '<svg xmlns="http://www.w3.org/2000/svg" viewBox="' + (x0 - pad) + " " + (-(y1 + pad)) + " " + w + " " + h + '">';
    const agents = meta.agents;
    for (const [agent, list] of Object.entries(paths)) {
      const colour = colours[Math.max(agents.indexOf(agent), 0) % colours.length];
      const points = list.map((p) => p.x + "," + (-p.y)).join(" ");
      const last = list[list.length - 1];
      svg += '<polyline points="' + points + '" fill="none" stroke="' + colour + '" stroke-width="' + (w / 300) + '"/>';
      svg += '<circle class="robot" data-agent="' + agent + '" cx="' + last.x + '" cy="' + (-last.y) + '" r="' + (w / 60) + '" fill="' + colour + '"/>';
      svg += '<text x="' + last.x + '" y="' + (-last.y - w / 25) + '" font-size="' + (w / 20) + '">' + agent + "</text>";
    }
    box.innerHTML = svg + "</svg>";
  }

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
    $("file").textContent = meta.file + " \u2014 " + meta.events + " events, " + meta.duration.toFixed(3) + " s";
    $("notes").textContent = (meta.notes || []).join(" ");
    $("kinds").textContent = "kinds: " + Object.entries(meta.kinds).map(([k, n]) => k + " (" + n + ")").join(", ");
    const slider = $("slider");
    slider.min = meta.start; slider.max = meta.end; slider.value = meta.start;
    slider.addEventListener("input", () => showState());
    $("filter").addEventListener("input", () => showLog(now()));
    $("play").addEventListener("click", () => { if (now() >= meta.end) { slider.value = meta.start; } setPlaying(!playing); });
    $("next-fault").addEventListener("click", () => jump("fault"));
    $("next-replan").addEventListener("click", () => jump("replan"));
    await showState();
    document.body.dataset.ready = "yes";
  }

  start().catch((err) => { document.body.insertAdjacentHTML("afterbegin", '<p class="note">' + err + "</p>"); });
})();

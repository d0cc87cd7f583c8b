// The control center's views: plain functions that draw a team snapshot (TeamView.snapshot) into DOM elements.
// The replay page (replay.js) and the live page call them alike: window.AlicaViews.
//   agents(tbody, snapshot)             the agents table (one row per agent, tr[data-agent])
//   tracks(events, t)                   {agent: [[t, x, y], ...]} from the pose events up to t
//   map(box, snapshot, tracks, meta)    top view: occupancy cells, objects, samples, robots and their tracks
//   blocks(box, snapshot, meta)         side view of the blocks world's blocks (x across, z up)
//   trees(box, snapshot, trees)         each agent's plan tree (GET /api/trees), its plans and states highlighted
//   log(tbody, events, filter, t)       the events up to t (all without t), newest first, filtered by text
"use strict";
(function () {
  const COLOURS = ["#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#8c564b", "#e377c2", "#17becf"];
  const SVG = "http://www.w3.org/2000/svg";

  function esc(text) {
    return String(text).replace(/[&<>"']/g, (c) => ({ "&": "&amp;", "<": "&lt;", ">": "&gt;", '"': "&quot;", "'": "&#39;" })[c]);
  }

  function num(v) { return Math.round(v * 1000) / 1000; }

  function cell(text) {
    const td = document.createElement("td");
    td.textContent = text == null ? "-" : String(text);
    return td;
  }

  function colour(names, name) { return COLOURS[Math.max(names.indexOf(name), 0) % COLOURS.length]; }

  function agents(tbody, snapshot) {
    tbody.replaceChildren();
    for (const [name, a] of Object.entries(snapshot.agents)) {
      const tr = document.createElement("tr");
      tr.dataset.agent = name;
      if (!a.alive) { tr.className = "dead"; }
      for (const v of [name, a.role, a.task, a.alive ? "yes" : "no", a.plan, a.state, a.behaviour]) { tr.appendChild(cell(v)); }
      tr.children[4].title = (a.plans || []).map((p) => p.plan + (p.state ? ": " + p.state : "")).join(" \u203a ");
      tbody.appendChild(tr);
    }
  }

  function tracks(events, t) {
    const out = {};
    for (const e of events) {
      if (t != null && e.t > t) { break; }
      if (e.event === "pose" && typeof e.x === "number" && typeof e.y === "number") {
        (out[e.agent] = out[e.agent] || []).push([e.t, e.x, e.y]);
      }
    }
    return out;
  }

  // The field to show: the header's bounds, else meta.extent ([x0, y0, x1, y1] of the whole trace), else what is drawn now.
  function field(snapshot, tracksNow, meta) {
    const header = (meta && meta.header) || {};
    const given = snapshot.bounds || header.bounds || (meta && meta.extent);
    if (Array.isArray(given) && given.length === 4) { return given; }
    let x0 = Infinity, y0 = Infinity, x1 = -Infinity, y1 = -Infinity;
    const see = (x, y) => { x0 = Math.min(x0, x); x1 = Math.max(x1, x); y0 = Math.min(y0, y); y1 = Math.max(y1, y); };
    for (const list of Object.values(tracksNow || {})) { for (const p of list) { see(p[1], p[2]); } }
    for (const o of Object.values(snapshot.objects || {})) { if (typeof o.x === "number") { see(o.x, o.y); } }
    for (const a of Object.values(snapshot.agents || {})) { if (a.pose && typeof a.pose.x === "number") { see(a.pose.x, a.pose.y); } }
    const m = snapshot.map;
    if (m) { see(m.origin[0], m.origin[1]); see(m.origin[0] + m.width * m.resolution, m.origin[1] + m.height * m.resolution); }
    return x0 === Infinity ? null : [x0 - 1, y0 - 1, Math.max(x1, x0 + 1) + 1, Math.max(y1, y0 + 1) + 1];
  }

  // The occupancy grid as runs of equal cells along each row: one rect a run, free light, occupied dark.
  function gridCells(m) {
    let out = '<g class="grid" data-free="' + m.free + '" data-occupied="' + m.occupied + '">';
    const r = m.resolution;
    for (let j = 0; j < m.height; j++) {
      const row = m.cells.substr(j * m.width, m.width);
      let i = 0;
      while (i < m.width) {
        const c = row[i];
        let k = i + 1;
        while (k < m.width && row[k] === c) { k++; }
        if (c === "1" || c === "2") {
          const x = m.origin[0] + i * r, y = m.origin[1] + (j + 1) * r;
          out += '<rect class="' + (c === "2" ? "occupied" : "free") + '" x="' + num(x) + '" y="' + num(-y) + '" width="' + num((k - i) * r) +
            '" height="' + num(r) + '"/>';
        }
        i = k;
      }
    }
    return out + "</g>";
  }

  function map(box, snapshot, tracksNow, meta) {
    const bounds = field(snapshot, tracksNow, meta);
    if (bounds === null) {
      box.innerHTML = '<p class="note">no poses in this trace</p>';
      return;
    }
    const [x0, y0, x1, y1] = bounds;
    const w = x1 - x0, h = y1 - y0, unit = Math.max(w, h);
    const names = (meta && meta.agents) || Object.keys(snapshot.agents);
    let svg = '<svg xmlns="' + SVG + '" class="map" viewBox="' + num(x0) + " " + num(-y1) + " " + num(w) + " " + num(h) + '" preserveAspectRatio="xMidYMid meet">';
    svg += '<rect class="field" x="' + num(x0) + '" y="' + num(-y1) + '" width="' + num(w) + '" height="' + num(h) + '"/>';
    if (snapshot.map) { svg += gridCells(snapshot.map); }
    const font = num(unit / 40);
    for (const [name, o] of Object.entries(snapshot.objects || {})) {
      if (typeof o.x !== "number" || typeof o.y !== "number") { continue; }
      const kind = o.kind || "object";
      const r = Math.max(typeof o.radius === "number" ? o.radius : (o.size || 0) / 2, unit / 150);
      const label = o.found !== undefined ? name + ": " + (o.found || "?") : (kind === "rock" ? "" : name);
      svg += '<g class="object ' + esc(kind) + (o.found !== undefined ? " found" : "") + '" data-name="' + esc(name) + '">';
      svg += '<circle cx="' + num(o.x) + '" cy="' + num(-o.y) + '" r="' + num(r) + '"/>';
      if (label) { svg += '<text x="' + num(o.x + r) + '" y="' + num(-o.y - r) + '" font-size="' + font + '">' + esc(label) + "</text>"; }
      svg += "</g>";
    }
    for (const [agent, list] of Object.entries(tracksNow || {})) {
      if (!list.length) { continue; }
      const c = colour(names, agent);
      svg += '<polyline class="track" data-agent="' + esc(agent) + '" points="' + list.map((p) => num(p[1]) + "," + num(-p[2])).join(" ") +
        '" fill="none" stroke="' + c + '" stroke-width="' + num(unit / 300) + '"/>';
    }
    for (const [agent, a] of Object.entries(snapshot.agents || {})) {
      const p = a.pose;
      if (!p || typeof p.x !== "number") { continue; }
      const c = colour(names, agent), r = unit / 60;
      svg += '<circle class="robot' + (a.alive ? "" : " dead") + '" data-agent="' + esc(agent) + '" cx="' + num(p.x) + '" cy="' + num(-p.y) + '" r="' + num(r) + '" fill="' + c + '"/>';
      if (typeof p.yaw === "number") {
        svg += '<line class="heading" x1="' + num(p.x) + '" y1="' + num(-p.y) + '" x2="' + num(p.x + 2 * r * Math.cos(p.yaw)) + '" y2="' + num(-p.y - 2 * r * Math.sin(p.yaw)) +
          '" stroke="' + c + '" stroke-width="' + num(unit / 200) + '"/>';
      }
      svg += '<text class="robot-name" x="' + num(p.x) + '" y="' + num(-p.y - 1.5 * r) + '" font-size="' + num(unit / 25) + '">' + esc(agent) + "</text>";
    }
    box.innerHTML = svg + "</svg>";
  }

  function blocks(box, snapshot, meta) {
    const list = Object.entries(snapshot.objects || {}).filter(([, o]) => o.kind === "block" && typeof o.x === "number" && typeof o.z === "number");
    if (!list.length) {
      box.innerHTML = '<p class="note">no blocks placed yet</p>';
      return;
    }
    const size = (o) => (typeof o.size === "number" && o.size > 0 ? o.size : 0.05);
    let x0 = Infinity, x1 = -Infinity, z1 = 0;
    for (const [, o] of list) { x0 = Math.min(x0, o.x - size(o)); x1 = Math.max(x1, o.x + size(o)); z1 = Math.max(z1, o.z + size(o)); }
    const pad = Math.max((x1 - x0) * 0.1, 0.1), w = x1 - x0 + 2 * pad, h = Math.max(z1, 0.2) + pad;
    let svg = '<svg xmlns="' + SVG + '" class="blocks" viewBox="' + num(x0 - pad) + " " + num(-h) + " " + num(w) + " " + num(h + pad / 2) + '" preserveAspectRatio="xMidYMax meet">';
    svg += '<line class="floor" x1="' + num(x0 - pad) + '" y1="0" x2="' + num(x1 + pad) + '" y2="0" stroke-width="' + num(w / 300) + '"/>';
    for (const [name, o] of list.sort((a, b) => a[1].x - b[1].x)) {
      const s = size(o);
      svg += '<g class="block" data-name="' + esc(name) + '"><rect x="' + num(o.x - s / 2) + '" y="' + num(-o.z - s / 2) + '" width="' + num(s) + '" height="' + num(s) +
        '" stroke-width="' + num(s / 20) + '"/><text x="' + num(o.x) + '" y="' + num(-o.z + s * 0.2) + '" font-size="' + num(s * 0.6) + '" text-anchor="middle">' + esc(name) + "</text></g>";
    }
    const header = (meta && meta.header) || {};
    let caption = "";
    if (Array.isArray(header.goal)) { caption = '<p class="goal">goal: ' + header.goal.map((s) => "[" + s.map(esc).join(" ") + "]").join(" ") + " (stacks, bottom first)</p>"; }
    box.innerHTML = svg + "</svg>" + caption;
  }

  // Each agent's plan tree as nested lists; the plan nodes the agent is in are .active, their current states .current.
  // A generated plan (a planning problem's plan, not in the plan file) is shown under its problem with its state.
  function trees(box, snapshot, data) {
    box.replaceChildren();
    const roots = (data && data.agents) || {};
    if (!Object.keys(roots).length) {
      box.innerHTML = '<p class="note">no plan trees' + (data && data.notes && data.notes.length ? ": " + esc(data.notes.join(" ")) : "") + "</p>";
      return;
    }
    for (const [agent, root] of Object.entries(roots)) {
      const a = snapshot.agents[agent];
      const active = {};
      for (const p of (a && a.plans) || []) { active[p.key] = p; }
      const claimed = new Set();
      const div = document.createElement("div");
      div.className = "agent-tree" + (a && !a.alive ? " dead" : "");
      div.dataset.agent = agent;
      let html = "<h3>" + esc(agent) + (a && !a.alive ? " (down)" : "") + "</h3><ul class=\"tree\">";
      html += node(data.trees[root], root, active, claimed);
      html += "</ul>";
      const rest = Object.values(active).filter((p) => !claimed.has(p.key));
      if (rest.length) { html += '<ul class="tree other">' + rest.map((p) => runtime(p, "other")).join("") + "</ul>"; }
      div.innerHTML = html;
      box.appendChild(div);
    }
  }

  function runtime(p, what) {
    return '<li class="plan ' + what + ' active" data-key="' + esc(p.key) + '"><span class="name">' + esc(p.plan) + "</span>" +
      (p.task ? ' <span class="task">task ' + esc(p.task) + "</span>" : "") +
      (p.state ? '<ul><li class="state current"><span class="name">' + esc(p.state) + "</span></li></ul>" : "") + "</li>";
  }

  function node(n, key, active, claimed) {
    if (!n) { return ""; }
    const here = active[key];
    if (n.kind === "behaviour") {
      return '<li class="behaviour" data-name="' + esc(n.name) + '"><span class="name">' + esc(n.name) + "</span></li>";
    }
    if (n.kind === "ref") {
      return '<li class="ref" data-name="' + esc(n.name) + '"><span class="name">' + esc(n.name) + " (above)</span></li>";
    }
    if (n.kind === "plantype" || n.kind === "problem") {
      const names = n.children.map((c) => c.name);
      let out = '<li class="' + n.kind + (here ? " active" : "") + '" data-key="' + esc(key) + '"><span class="name">' + (n.kind === "problem" ? "problem " : "plan type ") + esc(n.name) + "</span><ul>";
      out += n.children.map((c) => node(c, key, active, claimed)).join("");
      if (here && !names.includes(here.plan)) {
        // A generated plan: its states are not in the file; the plans it runs below its current state are.
        claimed.add(key);
        out += '<li class="plan generated active" data-key="' + esc(key) + '"><span class="name">' + esc(here.plan) + '</span> <span class="task">generated' +
          (here.task ? ", task " + esc(here.task) : "") + "</span><ul>";
        if (here.state) {
          out += '<li class="state current" data-state="' + esc(here.state) + '"><span class="name">' + esc(here.state) + "</span><ul>";
          for (const p of Object.values(active)) {
            const rest = p.key.startsWith(key + "/") ? p.key.slice(key.length + 1).split("/") : [];
            if (rest.length !== 2 || claimed.has(p.key)) { continue; }
            const tree = n.children.find((c) => c.name === p.plan || c.name === rest[1]);
            out += tree ? node(tree, p.key, active, claimed) : (claimed.add(p.key), runtime(p, "inside"));
          }
          out += "</ul></li>";
        }
        out += "</ul></li>";
      }
      return out + "</ul></li>";
    }
    const mine = here && here.plan === n.name;
    if (mine) { claimed.add(key); }
    let out = '<li class="plan' + (mine ? " active" : "") + '" data-key="' + esc(key) + '" data-name="' + esc(n.name) + '"><span class="name">' + esc(n.name) + "</span>";
    if (mine && here.task) { out += ' <span class="task">task ' + esc(here.task) + "</span>"; }
    out += "<ul>";
    // Before the plan's first transition the trace does not say its state: the entry point of the agent's task does.
    const entry = mine && !here.state ? ((n.entry_points || []).find((e) => e.name === here.task) || (n.entry_points || []).find((e) => e.task === here.task)) : null;
    const state = mine ? here.state || (entry ? entry.state : null) : null;
    for (const s of n.states) {
      const current = mine && state === s.name;
      out += '<li class="state ' + esc(s.kind) + (current ? " current" : "") + '" data-state="' + esc(s.name) + '"><span class="name">' + esc(s.name) + "</span>";
      if (s.children.length) {
        const below = "<ul>" + s.children.map((c) => node(c, key + "/" + s.name + "/" + c.name, active, claimed)).join("") + "</ul>";
        // what the agent is not in now folds away (a click opens it); the way to where it is stays open
        const inside = Object.keys(active).some((k) => k.startsWith(key + "/" + s.name + "/"));
        const leaves = s.children.every((c) => c.kind === "behaviour");
        out += current || inside || leaves ? below : "<details><summary>" + s.children.length + (s.children.length === 1 ? " child" : " children") + "</summary>" + below + "</details>";
      }
      out += "</li>";
    }
    return out + "</ul></li>";
  }

  function fields(e) {
    const rest = {};
    for (const k of Object.keys(e)) { if (k !== "t" && k !== "agent" && k !== "event") { rest[k] = e[k]; } }
    return JSON.stringify(rest);
  }

  const LOG_ROWS = 500;  // the log draws the newest rows up to the time; a long trace has tens of thousands

  // The index of the first event after time t (events are in time order), by bisection.
  function after(events, t) {
    let lo = 0, hi = events.length;
    while (lo < hi) {
      const mid = (lo + hi) >> 1;
      if (events[mid].t > t) { hi = mid; } else { lo = mid + 1; }
    }
    return lo;
  }

  function log(tbody, events, filter, t) {
    const text = (filter || "").trim().toLowerCase();
    const fragment = document.createDocumentFragment();
    let shown = 0, i = t == null ? events.length : after(events, t);
    while (i > 0 && shown < LOG_ROWS) {
      const e = events[--i];
      const rest = fields(e);
      if (text && !(e.event + " " + e.agent + " " + rest).toLowerCase().includes(text)) { continue; }
      const tr = document.createElement("tr");
      tr.className = "past";
      for (const v of [Number(e.t).toFixed(3), e.agent, e.event, rest]) { tr.appendChild(cell(v)); }
      fragment.appendChild(tr);
      shown += 1;
    }
    if (i > 0) {
      const tr = document.createElement("tr");
      tr.className = "more";
      const td = cell("the newest " + LOG_ROWS + " rows are shown; narrow the filter to see older events");
      td.colSpan = 4;
      tr.appendChild(td);
      fragment.appendChild(tr);
    }
    tbody.replaceChildren(fragment);
    tbody.dataset.shown = String(shown);
  }

  // The operator's side at this moment: goals set, plans waiting for review, the plans the team runs.
  function operator(box, snapshot) {
    const op = snapshot.operator || { proposals: {}, goals: {}, running: {} };
    let html = "";
    for (const [problem, goal] of Object.entries(op.goals)) {
      html += '<p class="goal">' + esc(problem) + ": the operator's goal <code>" + esc(goal) + "</code></p>";
    }
    for (const [problem, p] of Object.entries(op.proposals)) {
      html += '<div class="proposal" data-problem="' + esc(problem) + '" data-generation="' + p.generation + '">' +
        "<h3>" + esc(problem) + ": plan " + p.generation + " proposed by " + esc(p.leader) + " (cost " + p.cost +
        "), waiting for the operator</h3>" + (p.error ? '<p class="note bad">the change was refused: ' +
        esc(p.error) + "</p>" : "") + "<ol>" + p.steps.map((s) => "<li><code>" + esc(s) + "</code></li>").join("") +
        "</ol></div>";
    }
    for (const [problem, r] of Object.entries(op.running)) {
      html += '<p class="running" data-problem="' + esc(problem) + '">' + esc(problem) + ": the team runs plan " +
        r.generation + "." + r.version + " of " + esc(r.leader) + " (cost " + r.cost + ", " + r.steps +
        " steps) since t = " + num(r.t) + " s</p>";
    }
    box.innerHTML = html;
    box.hidden = html === "";
  }

  window.AlicaViews = { agents, tracks, map, blocks, trees, log, operator };
})();

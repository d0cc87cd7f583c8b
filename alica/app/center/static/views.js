// The control center's views: plain functions that draw a team snapshot (TeamView.snapshot) into DOM elements.
// The replay page (replay.js) and the live page call them alike: window.AlicaViews.
//   agents(tbody, snapshot)             the agents table (one row per agent, tr[data-agent])
//   tracks(events, t)                   {agent: [[t, x, y], ...]} from the pose events up to t
//   map(box, snapshot, tracks, meta)    top view: occupancy cells, objects, samples, robots and their tracks
//   blocks(box, snapshot, meta)         side view of the blocks world's blocks (x across, z up)
//   trees(box, snapshot, trees)         each agent's plan tree (GET /api/trees), its plans and states highlighted
//   log(tbody, events, filter, t, raw)  the events up to t (all without t), newest first, filtered by text; each a
//                                       line of text (eventText); pose rows and map payloads only with raw
//   eventText(event, raw)               one event as one line: "12.30 s  scout  transition Explore -> Return",
//                                       "3.10 s  a  reload adopted dc5a… -> 0e03… (changed plan Gate)"
//   placeLabels(items)                  label boxes that do not overlap (the map's greedy label placement)
//   scaleLength(width)                  a round length in metres for a scale bar on a field this wide
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

  // A cell whose text may wrap inside names too: after _ / - . and between a lower-case letter and a capital
  // (GetObjects_g1v1_amparo, DriveToObject), so that the agents table narrows without clipping.
  function wrapCell(text) {
    const td = document.createElement("td");
    const parts = (text == null ? "-" : String(text)).split(/(?<=[_/.-])|(?<=[a-z])(?=[A-Z])/);
    parts.forEach((part, i) => {
      if (i > 0) { td.appendChild(document.createElement("wbr")); }
      td.appendChild(document.createTextNode(part));
    });
    return td;
  }

  function colour(names, name) { return COLOURS[Math.max(names.indexOf(name), 0) % COLOURS.length]; }

  function agents(tbody, snapshot) {
    tbody.replaceChildren();
    for (const [name, a] of Object.entries(snapshot.agents)) {
      const tr = document.createElement("tr");
      tr.dataset.agent = name;
      if (!a.alive) { tr.className = "dead"; }
      for (const v of [name, a.role, a.task, a.alive ? "yes" : "no", a.plan, a.state, a.behaviour]) { tr.appendChild(wrapCell(v)); }
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
    svg += '<g class="leaders"></g>';
    const font = num(unit / 40);
    for (const [name, o] of Object.entries(snapshot.objects || {})) {
      if (typeof o.x !== "number" || typeof o.y !== "number") { continue; }
      const kind = o.kind || "object";
      const r = Math.max(typeof o.radius === "number" ? o.radius : (o.size || 0) / 2, unit / 150);
      const label = o.found !== undefined ? name + ": " + (o.found || "?") : (kind === "rock" ? "" : name);
      svg += '<g class="object ' + esc(kind) + (o.found !== undefined ? " found" : "") + '" data-name="' + esc(name) + '">';
      svg += '<circle cx="' + num(o.x) + '" cy="' + num(-o.y) + '" r="' + num(r) + '"/>';
      if (label) { svg += labelText("object-name", o.x, o.y, r, o.found !== undefined ? 1 : 2, font, label); }
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
      svg += labelText("robot-name", p.x, p.y, r, 0, num(unit / 25), agent);
    }
    svg += scaleBar(x0, y0, w, h);
    box.innerHTML = svg + "</svg>";
    arrange(box.querySelector("svg.map"), unit, { x: x0, y: -y1, w, h });
  }

  // A label's text at its anchor (the point it names, a disc of radius r there); arrange() moves it.
  // Priority: 0 robots, 1 found samples, 2 other objects (placed in that order).
  function labelText(cls, x, y, r, priority, font, text) {
    return '<text class="label ' + cls + '" x="' + num(x) + '" y="' + num(-y) + '" data-ax="' + num(x) + '" data-ay="' + num(-y) + '" data-r="' + num(r) +
      '" data-priority="' + priority + '" font-size="' + font + '">' + esc(text) + "</text>";
  }

  // A round length for a scale bar on a field `width` metres wide: 1, 2 or 5 times a power of ten, near a fifth of it.
  function scaleLength(width) {
    const target = width / 5;
    if (!(target > 0)) { return 1; }
    const power = Math.pow(10, Math.floor(Math.log10(target)));
    return [5, 2, 1].map((m) => m * power).find((v) => v <= target) || power;
  }

  // The scale bar in the field's lower left corner (SVG units are metres, y downwards).
  function scaleBar(x0, y0, w, h) {
    const length = scaleLength(w), unit = Math.max(w, h);
    const left = x0 + w * 0.04, base = -y0 - h * 0.04, tick = unit / 80, stroke = unit / 300, font = unit / 35;
    const text = String(Number(length.toPrecision(3))) + " m";
    return '<g class="scale-bar" data-metres="' + length + '">' +
      '<rect x="' + num(left - tick) + '" y="' + num(base - tick - 1.6 * font) + '" width="' + num(length + 2 * tick) + '" height="' + num(2 * tick + 1.6 * font) +
      '" fill="#fff" fill-opacity="0.75"/>' +
      '<path class="bar" d="M' + num(left) + "," + num(base - tick) + " V" + num(base) + " H" + num(left + length) + " V" + num(base - tick) +
      '" fill="none" stroke="#222" stroke-width="' + num(stroke) + '"/>' +
      '<text x="' + num(left + length / 2) + '" y="' + num(base - tick - 0.3 * font) + '" font-size="' + num(font) + '" text-anchor="middle">' + text + "</text></g>";
  }

  // Label placement, greedy: each label (in the order given) takes the first of its candidate positions, nearest
  // to its anchor first, whose box overlaps no box placed before it and no anchor disc; when every candidate
  // overlaps, the one that overlaps least. items: [{ax, ay, r, w, h}] (SVG units, y downwards); the anchor discs of
  // the other labels are kept clear too, and so is the outside of `field` ({x, y, w, h}) when given. Returns
  // [{x, y, w, h, moved}]: each box's top left corner, and whether it is off its first place (then the map draws
  // a leader line to the anchor).
  function placeLabels(items, field) {
    const placed = [];
    const discs = items.map((it) => ({ x: it.ax - it.r, y: it.ay - it.r, w: 2 * it.r, h: 2 * it.r }));
    const DIRS = [[1, -1], [1, 0], [1, 1], [0, -1], [0, 1], [-1, -1], [-1, 0], [-1, 1]];
    const overlap = (a, b) => Math.max(0, Math.min(a.x + a.w, b.x + b.w) - Math.max(a.x, b.x)) * Math.max(0, Math.min(a.y + a.h, b.y + b.h) - Math.max(a.y, b.y));
    const out = [];
    items.forEach((it, index) => {
      const gap = Math.max(it.h * 0.15, it.r * 0.3);
      let best = null, bestCost = Infinity;
      search:
      for (const level of [1, 2, 3, 4.5, 6.5, 9]) {
        const d = it.r + gap * level + (level > 1 ? it.h * (level - 1) * 0.5 : 0);
        for (const [dx, dy] of DIRS) {
          const box = {
            x: it.ax + dx * d * (dy === 0 ? 1 : 0.7) - (dx < 0 ? it.w : dx === 0 ? it.w / 2 : 0),
            y: it.ay + dy * d * (dx === 0 ? 1 : 0.7) - (dy < 0 ? it.h : dy === 0 ? it.h / 2 : 0),
            w: it.w, h: it.h, moved: level > 1,
          };
          let cost = 0;
          for (const other of placed) { cost += overlap(box, other); }
          discs.forEach((disc, k) => { if (k !== index) { cost += overlap(box, disc); } });
          if (field) { cost += box.w * box.h - overlap(box, field); }
          if (cost < bestCost) { best = box; bestCost = cost; }
          if (cost <= 1e-9) { break search; }
        }
      }
      placed.push(best);
      out.push(best);
    });
    return out;
  }

  // Moves the map's labels (text.label, drawn at their anchors) apart with placeLabels; a moved label gets a leader line.
  function arrange(svg, unit, field) {
    if (!svg) { return; }
    const texts = [...svg.querySelectorAll("text.label")];
    texts.sort((a, b) => Number(a.dataset.priority) - Number(b.dataset.priority));
    const items = texts.map((t) => {
      const ax = Number(t.dataset.ax), ay = Number(t.dataset.ay), r = Number(t.dataset.r);
      let bbox = null;
      try { bbox = t.getBBox(); } catch (err) { bbox = null; }
      const font = Number(t.getAttribute("font-size"));
      const w = bbox && bbox.width > 0 ? bbox.width : 0.6 * font * t.textContent.length;
      const h = bbox && bbox.height > 0 ? bbox.height : 1.2 * font;
      const dy = bbox && bbox.height > 0 ? bbox.y - ay : -0.95 * font;  // the box's top above the baseline
      return { ax, ay, r, w, h, dy };
    });
    const boxes = placeLabels(items, field);
    const leaders = svg.querySelector("g.leaders");
    let lines = "";
    boxes.forEach((b, i) => {
      const t = texts[i], it = items[i];
      t.setAttribute("x", num(b.x));
      t.setAttribute("y", num(b.y - it.dy));
      t.dataset.moved = b.moved ? "yes" : "no";
      if (b.moved) {
        const px = Math.min(Math.max(it.ax, b.x), b.x + b.w), py = Math.min(Math.max(it.ay, b.y), b.y + b.h);
        lines += '<line class="leader" x1="' + num(it.ax) + '" y1="' + num(it.ay) + '" x2="' + num(px) + '" y2="' + num(py) + '" stroke="#666" stroke-width="' + num(unit / 600) + '"/>';
      }
    });
    if (leaders) { leaders.innerHTML = lines; }
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

  // -- the event log: one line of text an event --------------------------------------------------------------

  const SHORT = 60;  // characters of one field's value in a line (all of it with raw)
  const SKIP = new Set(["t", "agent", "event"]);

  function value(v, raw) {
    const text = typeof v === "string" ? v : JSON.stringify(v);
    return raw || text.length <= SHORT ? text : text.slice(0, SHORT - 1) + "\u2026";
  }

  // The fields of e but those named, as "k=v k=v" (each value cut to SHORT characters unless raw).
  function rest(e, named, raw) {
    const out = [];
    for (const k of Object.keys(e)) {
      if (SKIP.has(k) || named.includes(k) || e[k] === null || e[k] === undefined || e[k] === "") { continue; }
      out.push(k + "=" + value(e[k], raw));
    }
    return out.length ? " " + out.join(" ") : "";
  }

  function at(e) { return typeof e.x === "number" && typeof e.y === "number" ? " at (" + num(e.x) + ", " + num(e.y) + ")" : ""; }
  function why(text) { return text ? ": " + text : ""; }
  function where(e) { return e.plan ? " in " + e.plan : e.key ? " in " + e.key : ""; }

  // A library's digest, cut short for a line (the row's tooltip has all of it).
  function digest(d) { return d ? String(d).slice(0, 4) + "\u2026" : "?"; }
  // What a reload changed: "changed plan Gate; added plan Check".
  function changes(e) {
    const list = Object.entries(e.changes || {}).filter(([, keys]) => Array.isArray(keys) && keys.length);
    return list.length ? " (" + list.map(([what, keys]) => what + " " + keys.join(", ")).join("; ") + ")" : "";
  }

  // A hot reload's events (alica.engine.reload): proposed, agreed, waiting, adopted, invalid, and its notes.
  function reloadText(e) {
    switch (e.status) {
      case "proposed": return "reload proposed " + digest(e.library) + " -> " + digest(e.proposed) + changes(e);
      case "agreed": return "reload agreed on " + digest(e.proposed) + " at t=" + Number(e.at).toFixed(2);
      case "waiting": return "reload waiting: " + Object.entries(e.differ || {}).map(([a, d]) => a + " has " + digest(d)).join(", ") +
        " (not " + digest(e.proposed) + "; the team goes on with " + digest(e.library) + ")";
      case "adopted": return "reload adopted " + digest(e.library) + " -> " + digest(e.adopted) + changes(e) +
        (e.restarted && e.restarted.length ? " restarted " + e.restarted.join(", ") : "");
      case "invalid": return "reload invalid: " + (e.errors || []).join("; ");
      default: return "reload " + (e.key ? e.key + ": " : "") + (e.note || e.status || "");
    }
  }

  // What each kind of event says, without its time and agent (the fields it leaves out follow as k=v unless noted).
  const TEXTS = {
    transition: (e) => "transition " + e.source + " -> " + e.target + where(e),
    allocation: (e) => "allocation " + (e.plan || e.key) + ": " +
      Object.entries(e.entries || {}).map(([a, ep]) => a + " " + ep).join(", ") + (e.reason ? " (" + e.reason + ")" : "") +
      (e.outcome ? " " + e.outcome + why(e.why) : ""),
    behaviour: (e) => "behaviour " + e.behaviour + " " + e.status + why(e.reason),
    success: (e) => "success " + (e.plan || e.key),
    failure: (e) => "failure " + (e.plan || e.child || e.key) + why(e.reason),
    repair: (e) => "repair " + e.stage + " " + (e.plan || e.key) + why(e.reason),
    replan: (e) => "replan " + e.key + why(e.reason),
    fault: (e, raw) => "fault " + e.fault + rest(e, ["fault"], raw),
    team: (e) => "team " + e.change + " " + e.who,
    note: (e) => "note " + e.message,
    pose: (e) => "pose" + at(e) + (typeof e.yaw === "number" ? " yaw " + num(e.yaw) : "") + (e.alive === false ? " (down)" : ""),
    object: (e) => "object " + e.name + " " + (e.sample_kind || e.kind || "") + at(e),
    found: (e) => "found " + e.name + " " + (e.kind || "(kind not known yet)") + at(e),
    map: (e, raw) => "map " + e.width + " x " + e.height + " cells of " + e.resolution + " m" +
      (Array.isArray(e.origin) ? " from (" + e.origin.map(num).join(", ") + ")" : "") + (raw ? rest(e, ["width", "height", "resolution", "origin"], true) : ""),
    operator: (e, raw) => "operator " + (e.what || "facts") + rest(e, ["what"], raw),
    planner: (e, raw) => "planner " + e.what + " " + e.key + rest(e, ["what", "key"], raw),
    reload: reloadText,
  };

  // One event as one line of text: "12.30 s  scout  transition Explore -> Return in Mission".
  function eventText(e, raw) {
    const say = TEXTS[e.event];
    let text;
    try { text = say ? say(e, raw) : e.event + rest(e, [], raw); } catch (err) { text = e.event + rest(e, [], raw); }
    return Number(e.t).toFixed(2).padStart(7) + " s  " + String(e.agent).padEnd(8) + "  " + text;
  }

  // Pose rows are left out of the log unless raw.
  function logged(e, raw) { return raw || e.event !== "pose"; }

  // A row of the log: the event's line, its kind and agent as data, the whole event (without a map's cells unless raw)
  // as the row's tooltip.
  function logRow(e, raw) {
    const tr = document.createElement("tr");
    tr.dataset.kind = e.event;
    tr.dataset.agent = e.agent;
    const td = document.createElement("td");
    td.className = "line";
    td.textContent = eventText(e, raw);
    tr.title = JSON.stringify(raw || e.event !== "map" ? e : Object.assign({}, e, { cells: "(" + String(e.cells || "").length + " characters)" }));
    tr.appendChild(td);
    return tr;
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

  function log(tbody, events, filter, t, raw) {
    const text = (filter || "").trim().toLowerCase();
    const fragment = document.createDocumentFragment();
    let shown = 0, i = t == null ? events.length : after(events, t);
    while (i > 0 && shown < LOG_ROWS) {
      const e = events[--i];
      if (!logged(e, raw)) { continue; }
      if (text && !(e.event + " " + eventText(e, raw)).toLowerCase().includes(text)) { continue; }
      const tr = logRow(e, raw);
      tr.className = "past";
      fragment.appendChild(tr);
      shown += 1;
    }
    if (i > 0) {
      const tr = document.createElement("tr");
      tr.className = "more";
      const td = cell("the newest " + LOG_ROWS + " rows are shown; narrow the filter to see older events");
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

  window.AlicaViews = { agents, tracks, map, blocks, trees, log, operator, eventText, logged, logRow, placeLabels, scaleLength };
})();

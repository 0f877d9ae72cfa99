"""The live view's page: one HTML file with its script inline (nothing fetched from outside).

The script opens ``/ws``, merges each message into its copy of the state (new track points are
appended; a track sent from its start replaces the old one) and redraws: the floor plan of the floor
shown (the site's walls of that floor, its doors, stairs and elevators as marked discs), the truth when
the log has it, and every scheme's track on that floor (the primary pose's floor unless a floor button
was pressed), each in its registry colour; x/y axes in metres with ticks and a scale bar. A checkbox
per scheme shows or hides its track (the primary pose's stays on); the wheel or the +/- buttons zoom
(about the cursor, or the centre), dragging pans, "fit" shows everything again. Beside the map: the
primary's floor and scheme, the step count, the FIX verdicts per scheme and source, the latest fix
records, the HEALTH counters and the context; the messages skipped as undecodable (``bad``). A value
the server sends as null (it was NaN or infinite) shows as "–". Element ids (``status``, ``bad``,
``floor``, ``steps``,
``primary``, ``schemes``, ``toggles``, ``zoom-in``, ``zoom-out``, ``zoom-fit``, ``scale-label``,
``fix-table``, ``recent-fixes``, ``health-table``, ``context``, ``map``) are what the browser test
reads; after each drawing the map's ``data-`` attributes say what it drew (``tracks``: the schemes,
``walls`` and ``ports``: the plan's of the floor shown, ``floor``, ``scale-m``: the scale bar [m],
``xticks``, ``yticks``: the axes' tick values [m]).
"""

PAGE = r"""<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>StrideFix live</title>
<style>
body { font-family: system-ui, -apple-system, 'Segoe UI', sans-serif; margin: 1em; color: #222; }
h1 { font-size: 1.3em; margin: 0 0 0.3em 0; } h2 { font-size: 1em; margin: 0.8em 0 0.2em 0; }
#wrap { display: flex; gap: 1.2em; align-items: flex-start; flex-wrap: wrap; }
canvas { border: 1px solid #ccc; background: #fff; }
table { border-collapse: collapse; font-size: 0.85em; } th, td { border: 1px solid #ddd; padding: 0.15em 0.5em; text-align: right; }
th { background: #f4f4f4; } td.k { text-align: left; }
.big { font-size: 1.6em; font-weight: 600; } .note { color: #666; font-size: 0.85em; }
.sw { display: inline-block; width: 0.9em; height: 0.9em; margin-right: 0.4em; vertical-align: middle; }
#floors button { margin-right: 0.3em; } #floors button.on { font-weight: 700; background: #dde8ff; }
.rej { color: #a40; } .acc { color: #260; }
#controls { margin: 0.3em 0; font-size: 0.9em; } #controls button { min-width: 2em; }
#toggles label { margin-right: 0.8em; white-space: nowrap; } #toggles input:disabled + span { font-weight: 700; }
#map { cursor: grab; } #map.drag { cursor: grabbing; }
</style></head>
<body>
<h1>StrideFix live</h1>
<div class="note">source <span id="source">?</span> · <span id="status">connecting</span> · walk time <span id="time">–</span>
 · <span id="bad" title="messages that could not be decoded, skipped">0</span> bad messages</div>
<div id="wrap">
 <div><div id="floors"></div>
  <div id="controls"><button id="zoom-out" title="zoom out">−</button> <button id="zoom-in" title="zoom in">+</button>
   <button id="zoom-fit" title="show everything">fit</button>
   <span class="note">wheel: zoom, drag: pan · scale bar <span id="scale-label">–</span></span></div>
  <canvas id="map" width="760" height="580"></canvas>
  <div id="toggles" class="note"></div></div>
 <div>
  <div>floor <span id="floor" class="big">–</span> &nbsp; steps <span id="steps" class="big">0</span></div>
  <div class="note">primary pose: <span id="primary">–</span></div>
  <h2>Schemes</h2><table id="schemes"><tr><th class="k">scheme</th><th>floor</th><th>x [m]</th><th>y [m]</th><th>σ [m]</th><th>poses</th></tr></table>
  <h2>Fix verdicts</h2><table id="fix-table"><tr><th class="k">scheme</th><th class="k">source</th><th>offered</th><th>accepted</th><th>rejected</th><th class="k">why rejected</th></tr></table>
  <h2>Latest fixes</h2><table id="recent-fixes"><tr><th>t [s]</th><th class="k">scheme</th><th class="k">source</th><th class="k">verdict</th><th>test ratio</th><th>α</th></tr></table>
  <h2>Context</h2><div id="context" class="note">no CONTEXT message</div>
  <h2>Health</h2><table id="health-table"><tr><th class="k">counter</th><th>value</th></tr></table>
 </div>
</div>
<script>
"use strict";
const S = {schemes: {}, truth: [], walls: [], ports: [], floorPick: null, doc: null, hidden: new Set()};
// the view: zoom about the fitted scale and the centre's offset from the fitted centre [m]
const V = {zoom: 1, dx_m: 0, dy_m: 0, drag: null};
const M = {left: 48, right: 12, top: 10, bottom: 30};  // the axes' margins [px]
const PORT_LETTER = {door: "D", stairs: "S", elevator: "E"};
const $ = (id) => document.getElementById(id);
const esc = (s) => String(s).replace(/[&<>"]/g, (c) => ({"&": "&amp;", "<": "&lt;", ">": "&gt;", '"': "&quot;"}[c]));
const fmt = (v, d) => (v === null || v === undefined || !isFinite(v)) ? "–" : Number(v).toFixed(d);

function merge(doc) {
  for (const s of doc.schemes) {
    const mine = S.schemes[s.code] || (S.schemes[s.code] = {track: []});
    mine.track = s.track_start === 0 ? s.track.slice() : mine.track.concat(s.track);
    Object.assign(mine, {name: s.name, colour: s.colour, last: s.last, poses: s.poses});
  }
  S.truth = doc.truth.track_start === 0 ? doc.truth.track.slice() : S.truth.concat(doc.truth.track);
  S.walls = doc.walls; S.ports = doc.ports || []; S.doc = doc;
}

function floorShown() {
  const d = S.doc;
  if (S.floorPick !== null) return S.floorPick;
  if (d && d.primary) return d.primary.floor;
  return 0;
}

function floorsSeen() {
  const f = new Set();
  for (const w of S.walls) f.add(w[4]);
  for (const p of S.truth) f.add(p[2]);
  for (const s of Object.values(S.schemes)) for (const p of s.track) f.add(p[2]);
  return Array.from(f).sort((a, b) => a - b);
}

// the primary pose's scheme is always drawn; the others as their checkbox says
const primaryName = () => (S.doc && S.doc.primary ? S.doc.primary.scheme : null);
const shown = (name) => name === primaryName() || !S.hidden.has(name);

// 1, 2 or 5 × 10^k: the largest not above v (nice ticks and scale bars)
function nice(v) {
  const p = Math.pow(10, Math.floor(Math.log10(v)));
  for (const m of [5, 2, 1]) if (m * p <= v) return m * p;
  return p;
}

// the fitted view: every wall and track in the plot area, equal scale on x and y
function fitted(c) {
  let x0 = Infinity, x1 = -Infinity, y0 = Infinity, y1 = -Infinity;
  const add = (x, y) => { x0 = Math.min(x0, x); x1 = Math.max(x1, x); y0 = Math.min(y0, y); y1 = Math.max(y1, y); };
  for (const w of S.walls) { add(w[0], w[1]); add(w[2], w[3]); }
  for (const p of S.ports) add(p.x_m, p.y_m);
  for (const p of S.truth) add(p[0], p[1]);
  for (const s of Object.values(S.schemes)) for (const p of s.track) add(p[0], p[1]);
  if (x0 > x1) return null;
  const w = c.width - M.left - M.right, h = c.height - M.top - M.bottom;
  const k = Math.min(w / Math.max(x1 - x0 + 4, 1), h / Math.max(y1 - y0 + 4, 1));
  return {k: k, cx: (x0 + x1) / 2, cy: (y0 + y1) / 2};
}

// map frame [m] <-> canvas [px] under the current zoom and pan
function view(c) {
  const f = fitted(c);
  if (!f) return null;
  const k = f.k * V.zoom, cx = f.cx + V.dx_m, cy = f.cy + V.dy_m;
  const px0 = M.left + (c.width - M.left - M.right) / 2, py0 = M.top + (c.height - M.top - M.bottom) / 2;
  return {k: k, X: (x) => px0 + (x - cx) * k, Y: (y) => py0 - (y - cy) * k,
          x: (px) => cx + (px - px0) / k, y: (py) => cy - (py - py0) / k};
}

function axes(g, c, v) {
  const l = M.left, r = c.width - M.right, t = M.top, b = c.height - M.bottom;
  const step = nice(90 / v.k), ticks = {x: [], y: []};  // a tick every 36 to 90 px
  g.font = "11px system-ui, sans-serif"; g.lineWidth = 1;
  g.strokeStyle = "#eee"; g.fillStyle = "#555";
  g.textAlign = "center"; g.textBaseline = "top";
  for (let x = Math.ceil(v.x(l) / step) * step; x <= v.x(r); x += step) {
    const px = v.X(x); g.beginPath(); g.moveTo(px, t); g.lineTo(px, b); g.stroke();
    g.fillText(+x.toFixed(6) + "", px, b + 4); ticks.x.push(+x.toFixed(6));
  }
  g.textAlign = "right"; g.textBaseline = "middle";
  for (let y = Math.ceil(v.y(b) / step) * step; y <= v.y(t); y += step) {
    const py = v.Y(y); g.beginPath(); g.moveTo(l, py); g.lineTo(r, py); g.stroke();
    g.fillText(+y.toFixed(6) + "", l - 5, py); ticks.y.push(+y.toFixed(6));
  }
  g.strokeStyle = "#999"; g.strokeRect(l, t, r - l, b - t);
  g.textAlign = "left"; g.textBaseline = "alphabetic";
  g.fillText("x [m]", r - 30, c.height - 2);
  g.save(); g.translate(11, t + 30); g.rotate(-Math.PI / 2); g.textAlign = "right"; g.fillText("y [m]", 0, 0); g.restore();
  return ticks;
}

function scaleBar(g, c, v) {
  const m = nice(120 / v.k), px = m * v.k, x1 = c.width - M.right - 12, y = c.height - M.bottom - 12;
  const text = (m >= 1 ? +m.toFixed(0) : +m.toPrecision(1)) + " m";
  g.fillStyle = "rgba(255, 255, 255, 0.85)"; g.fillRect(x1 - px - 8, y - 22, px + 16, 30);  // over the tracks
  g.strokeStyle = "#222"; g.lineWidth = 3;
  g.beginPath(); g.moveTo(x1 - px, y); g.lineTo(x1, y); g.stroke();
  g.lineWidth = 1.5; g.beginPath(); g.moveTo(x1 - px, y - 5); g.lineTo(x1 - px, y + 5); g.moveTo(x1, y - 5); g.lineTo(x1, y + 5); g.stroke();
  g.fillStyle = "#222"; g.font = "12px system-ui, sans-serif"; g.textAlign = "center"; g.fillText(text, x1 - px / 2, y - 7);
  $("scale-label").textContent = text;
  return m;
}

function draw() {
  const c = $("map"), g = c.getContext("2d"), fl = floorShown();
  g.clearRect(0, 0, c.width, c.height);
  const v = view(c);
  if (!v) return;
  const ticks = axes(g, c, v);
  g.save(); g.beginPath(); g.rect(M.left, M.top, c.width - M.left - M.right, c.height - M.top - M.bottom); g.clip();
  const X = v.X, Y = v.Y;
  let walls = 0, ports = 0;
  g.strokeStyle = "#666"; g.lineWidth = 2;
  for (const w of S.walls) if (w[4] === fl) {
    g.beginPath(); g.moveTo(X(w[0]), Y(w[1])); g.lineTo(X(w[2]), Y(w[3])); g.stroke(); walls++;
  }
  for (const p of S.ports) if (p.floor_lo <= fl && fl <= p.floor_hi) {
    g.strokeStyle = "#7a3db8"; g.fillStyle = "rgba(122, 61, 184, 0.08)"; g.lineWidth = 1; g.setLineDash([4, 3]);
    g.beginPath(); g.arc(X(p.x_m), Y(p.y_m), Math.max(p.radius_m * v.k, 6), 0, 2 * Math.PI); g.fill(); g.stroke(); g.setLineDash([]);
    g.fillStyle = "#7a3db8"; g.font = "bold 12px system-ui, sans-serif"; g.textAlign = "center"; g.textBaseline = "middle";
    g.fillText(PORT_LETTER[p.kind] || "?", X(p.x_m), Y(p.y_m)); ports++;
  }
  g.textAlign = "left"; g.textBaseline = "alphabetic";
  const line = (pts, colour, width, alpha) => {
    g.strokeStyle = colour; g.lineWidth = width; g.globalAlpha = alpha; g.beginPath();
    let up = true;
    for (const p of pts) {
      if (p[2] !== fl) { up = true; continue; }
      if (up) g.moveTo(X(p[0]), Y(p[1])); else g.lineTo(X(p[0]), Y(p[1]));
      up = false;
    }
    g.stroke(); g.globalAlpha = 1;
  };
  if (!S.hidden.has("truth")) line(S.truth, "#000", 4, 0.25);
  const drawn = [];
  for (const s of Object.values(S.schemes)) {
    if (!shown(s.name)) continue;
    const primary = s.name === primaryName();
    line(s.track, s.colour, primary ? 2.6 : 1.6, 0.9);
    drawn.push(s.name);
    if (s.last && s.last.floor === fl && Number.isFinite(s.last.x_m) && Number.isFinite(s.last.y_m)) {
      g.fillStyle = s.colour; g.beginPath(); g.arc(X(s.last.x_m), Y(s.last.y_m), primary ? 7 : 5, 0, 2 * Math.PI); g.fill();
    }
  }
  g.restore();
  const m = scaleBar(g, c, v);
  Object.assign(c.dataset, {tracks: drawn.join(","), walls: walls, ports: ports, floor: fl, scaleM: m,
                            xticks: ticks.x.join(","), yticks: ticks.y.join(",")});
}

// zoom by f about the canvas point (px, py): the map point under it stays put
function zoomAt(f, px, py) {
  const c = $("map"), v = view(c);
  if (!v) return;
  const mx = v.x(px), my = v.y(py);
  V.zoom = Math.min(Math.max(V.zoom * f, 0.2), 200);
  const w = view(c);
  V.dx_m += mx - w.x(px); V.dy_m += my - w.y(py);
  draw();
}

function controls() {
  const c = $("map");
  const mid = () => [M.left + (c.width - M.left - M.right) / 2, M.top + (c.height - M.top - M.bottom) / 2];
  $("zoom-in").onclick = () => zoomAt(1.5, ...mid());
  $("zoom-out").onclick = () => zoomAt(1 / 1.5, ...mid());
  $("zoom-fit").onclick = () => { V.zoom = 1; V.dx_m = 0; V.dy_m = 0; draw(); };
  const at = (ev) => { const r = c.getBoundingClientRect(); return [(ev.clientX - r.left) * c.width / r.width, (ev.clientY - r.top) * c.height / r.height]; };
  c.addEventListener("wheel", (ev) => { ev.preventDefault(); zoomAt(Math.exp(-ev.deltaY * 0.0015), ...at(ev)); }, {passive: false});
  c.addEventListener("mousedown", (ev) => { V.drag = at(ev); c.classList.add("drag"); });
  window.addEventListener("mouseup", () => { V.drag = null; c.classList.remove("drag"); });
  window.addEventListener("mousemove", (ev) => {
    if (!V.drag) return;
    const p = at(ev), v = view(c);
    if (!v) return;
    V.dx_m -= (p[0] - V.drag[0]) / v.k; V.dy_m += (p[1] - V.drag[1]) / v.k; V.drag = p; draw();
  });
}

// a checkbox per scheme (and the truth): rebuilt only when the set of schemes or the primary changes
function toggles() {
  const names = ["truth", ...Object.values(S.schemes).map((s) => s.name)], key = names.join(",") + "|" + primaryName();
  const box = $("toggles");
  if (box.dataset.key === key) return;
  box.dataset.key = key;
  const colour = (n) => n === "truth" ? "#000" : Object.values(S.schemes).find((s) => s.name === n).colour;
  box.innerHTML = "tracks: " + names.map((n) => {
    const primary = n === primaryName();
    return `<label title="${primary ? "the primary pose: always shown" : "show or hide this track"}">` +
      `<input type="checkbox" data-scheme="${esc(n)}" ${S.hidden.has(n) && !primary ? "" : "checked"} ${primary ? "disabled" : ""}>` +
      `<span><span class="sw" style="background:${esc(colour(n))}"></span>${esc(n)}${primary ? " (primary)" : ""}</span></label>`;
  }).join("");
  for (const cb of box.querySelectorAll("input")) cb.onchange = () => {
    if (cb.checked) S.hidden.delete(cb.dataset.scheme); else S.hidden.add(cb.dataset.scheme);
    draw();
  };
}

function tables() {
  const d = S.doc;
  $("source").textContent = d.source;
  $("status").textContent = d.ended ? "log ended" : "live";
  $("bad").textContent = d.bad_messages;
  $("time").textContent = d.t_us === null ? "–" : fmt(d.t_us / 1e6, 1) + " s";
  $("steps").textContent = d.steps;
  $("floor").textContent = d.primary ? d.primary.floor : "–";
  $("primary").textContent = d.primary ? d.primary.scheme : "–";
  const fl = floorsSeen();
  $("floors").innerHTML = fl.map((f) => `<button data-floor="${f}" class="${f === floorShown() ? "on" : ""}">floor ${f}</button>`).join("") +
    (S.floorPick !== null ? '<button data-floor="follow">follow</button>' : "");
  for (const b of $("floors").querySelectorAll("button")) b.onclick = () => {
    S.floorPick = b.dataset.floor === "follow" ? null : Number(b.dataset.floor); tables(); draw();
  };
  let rows = '<tr><th class="k">scheme</th><th>floor</th><th>x [m]</th><th>y [m]</th><th>σ [m]</th><th>poses</th></tr>';
  for (const s of Object.values(S.schemes)) {
    const l = s.last || {};
    rows += `<tr data-scheme="${esc(s.name)}"><td class="k"><span class="sw" style="background:${esc(s.colour)}"></span>${esc(s.name)}</td>` +
      `<td>${l.floor ?? "–"}</td><td>${fmt(l.x_m, 2)}</td><td>${fmt(l.y_m, 2)}</td><td>${fmt(l.sigma_m, 2)}</td><td>${s.poses}</td></tr>`;
  }
  $("schemes").innerHTML = rows;
  rows = '<tr><th class="k">scheme</th><th class="k">source</th><th>offered</th><th>accepted</th><th>rejected</th><th class="k">why rejected</th></tr>';
  for (const [scheme, methods] of Object.entries(d.fix_counts)) for (const [m, c] of Object.entries(methods)) {
    const why = Object.entries(c.rejected_by_reason).map(([r, n]) => `${esc(r)} ${n}`).join(", ");
    rows += `<tr data-scheme="${esc(scheme)}" data-method="${esc(m)}"><td class="k">${esc(scheme)}</td><td class="k">${esc(m)}</td>` +
      `<td>${c.offered}</td><td>${c.accepted}</td><td>${c.rejected}</td><td class="k">${why}</td></tr>`;
  }
  $("fix-table").innerHTML = rows;
  rows = '<tr><th>t [s]</th><th class="k">scheme</th><th class="k">source</th><th class="k">verdict</th><th>test ratio</th><th>α</th></tr>';
  for (const f of d.recent_fixes) {
    rows += `<tr><td>${fmt(f.t_us / 1e6, 1)}</td><td class="k">${esc(f.scheme)}</td><td class="k">${esc(f.method)}</td>` +
      `<td class="k ${f.accepted ? "acc" : "rej"}">${f.accepted ? "accepted" : esc(f.reason)}</td><td>${fmt(f.test_ratio, 2)}</td><td>${fmt(f.alpha, 2)}</td></tr>`;
  }
  $("recent-fixes").innerHTML = rows;
  $("context").textContent = d.context ? `context ${d.context.context} (floor ${d.context.floor}), rule ${d.context.rule_text || d.context.rule}` : "no CONTEXT message";
  rows = '<tr><th class="k">counter</th><th>value</th></tr>';
  for (const [k, v] of Object.entries(d.health)) rows += `<tr data-key="${esc(k)}"><td class="k">${esc(k)}</td><td>${esc(v)}</td></tr>`;
  $("health-table").innerHTML = rows;
}

function connect() {
  const ws = new WebSocket((location.protocol === "https:" ? "wss://" : "ws://") + location.host + "/ws");
  ws.onmessage = (ev) => { merge(JSON.parse(ev.data)); tables(); toggles(); draw(); document.body.dataset.version = S.doc.version; };
  ws.onclose = () => { if (!(S.doc && S.doc.ended)) { $("status").textContent = "disconnected, retrying"; setTimeout(connect, 1000); } };
}
controls();
connect();
</script>
</body></html>
"""

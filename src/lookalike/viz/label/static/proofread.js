// The proofreading page (plain JavaScript, no build step, no network access beyond this server).
// Frames are 1-based; rows are [frame, id, x, y, w, h] in video pixels.
"use strict";

const WINDOW = 400, MAX_WIDTH = 960, MAX_HEIGHT = 600, LANE_PX = 12, MAX_LANES = 60;
const state = {
  meta: null, frame: 1, version: -1, picked: null, rows: new Map(), lo: 0, hi: -1, rowsVersion: -2,
  image: null, imageFrame: 0, doubtful: [], spans: {}, scale: 1,
};

function showMessage(text, ok) { $("message").textContent = text || ""; $("message").className = ok ? "ok" : ""; }
function colour(id) { const c = state.meta.colours; return c[((id % c.length) + c.length) % c.length]; }

async function rowsOf(k) {
  if (state.rowsVersion !== state.version || k < state.lo || k > state.hi) {
    const start = Math.max(1, k - WINDOW / 4);
    const d = await api(`api/tracks?start=${start}&count=${WINDOW}`);
    state.rows = new Map();
    for (const r of d.rows) {
      if (!state.rows.has(r[0])) state.rows.set(r[0], []);
      state.rows.get(r[0]).push(r);
    }
    state.lo = start; state.hi = start + WINDOW - 1; state.rowsVersion = d.version;
  }
  return state.rows.get(k) || [];
}

function loadImage(k) {
  return new Promise((resolve) => {
    const img = new Image();
    img.onload = () => resolve(img);
    img.onerror = () => resolve(null);
    img.src = `api/frame?k=${k}`;
  });
}

function draw(rows) {
  const cv = $("view"), ctx = cv.getContext("2d"), s = state.scale;
  ctx.fillStyle = "#111"; ctx.fillRect(0, 0, cv.width, cv.height);
  if (state.image) ctx.drawImage(state.image, 0, 0, cv.width, cv.height);
  ctx.font = "bold 13px system-ui, sans-serif";
  for (const [, id, x, y, w, h] of rows) {
    const picked = id === state.picked;
    ctx.lineWidth = picked ? 4 : 2;
    ctx.strokeStyle = "#141414"; ctx.strokeRect(x * s - 1, y * s - 1, w * s + 2, h * s + 2);
    ctx.strokeStyle = colour(id); ctx.strokeRect(x * s, y * s, w * s, h * s);
    ctx.fillStyle = "#141414"; ctx.fillRect(x * s, y * s - 16, 8 + 8 * String(id).length, 16);
    ctx.fillStyle = colour(id); ctx.fillText(String(id), x * s + 4, y * s - 3);
  }
  const body = $("boxes").querySelector("tbody");
  body.replaceChildren(...rows.map(([, id, x, y, w, h]) => {
    const tr = document.createElement("tr");
    Object.assign(tr.dataset, { id, sx: (x + w / 2) * s, sy: (y + h / 2) * s });
    if (id === state.picked) tr.className = "picked";
    tr.innerHTML = `<td><span class="swatch"></span> ${id}</td><td>${x}, ${y}, ${w}, ${h}</td>`;
    tr.querySelector(".swatch").style.background = colour(id);
    tr.onclick = () => pick(id);
    return tr;
  }));
}

async function show(k) {
  k = Math.min(Math.max(1, k), state.meta.n_frames);
  state.frame = k;
  $("frame-index").textContent = k; $("from-frame").textContent = k;
  const [img, rows] = await Promise.all([state.imageFrame === k ? state.image : loadImage(k), rowsOf(k)]);
  if (state.frame !== k) return;  // a later frame was asked for meanwhile
  state.image = img; state.imageFrame = k;
  draw(rows);
  drawTimeline();
  history.replaceState(null, "", `#frame=${k}`);
  document.body.dataset.frame = k;
  document.body.dataset.shown = `${k}:${state.rowsVersion}`;
}

// One lane per id (the first MAX_LANES): its runs of frames in its colour, doubtful ranges in red below them, and
// the frame shown as a line. A click goes to that frame and picks that id.
function lanes() { return Object.keys(state.spans).map(Number).slice(0, MAX_LANES); }

function drawTimeline() {
  const cv = $("timeline"), ctx = cv.getContext("2d"), ids = lanes(), n = state.meta.n_frames;
  cv.height = Math.max(1, ids.length) * LANE_PX;
  const x = (f) => ((f - 1) / Math.max(1, n - 1)) * (cv.width - 2) + 1;
  ctx.fillStyle = "#333"; ctx.fillRect(0, 0, cv.width, cv.height);
  ids.forEach((id, lane) => {
    const y = lane * LANE_PX;
    ctx.fillStyle = colour(id);
    for (const [a, b] of state.spans[id]) ctx.fillRect(x(a), y + 1, Math.max(1, x(b) - x(a)), LANE_PX - 5);
    ctx.fillStyle = "#f33";
    for (const d of state.doubtful) {
      if (d.track === id) ctx.fillRect(x(d.first), y + LANE_PX - 4, Math.max(2, x(d.last) - x(d.first)), 3);
    }
  });
  ctx.fillStyle = "#fff"; ctx.fillRect(x(state.frame) - 1, 0, 2, cv.height);
}

function onTimeline(ev) {
  const cv = $("timeline"), r = cv.getBoundingClientRect(), ids = lanes();
  const f = Math.round(((ev.clientX - r.left - 1) / (cv.width - 2)) * (state.meta.n_frames - 1)) + 1;
  const id = ids[Math.floor((ev.clientY - r.top) / LANE_PX)];
  if (id !== undefined) state.picked = id;
  $("picked").textContent = state.picked === null ? "none (click a box)" : String(state.picked);
  show(f);
}

function pick(id) {
  state.picked = id;
  $("picked").textContent = id === null ? "none (click a box)" : String(id);
  show(state.frame);
}

async function refresh() {
  const s = await api("api/state");
  state.version = s.version; state.doubtful = s.doubtful;
  $("corrections").replaceChildren(...s.corrections.map((c) => {
    const li = document.createElement("li");
    const other = c.other === undefined ? "" : ` ${c.other}`, from = c.frame === undefined ? "" : ` from ${c.frame}`;
    li.textContent = `${c.kind} ${c.track}${other}${from}` + (c.dropped ? " (dropped by a later one)" : "");
    if (c.dropped) li.className = "dropped";
    return li;
  }));
  state.spans = s.spans;
  if (state.picked !== null && !(String(state.picked) in s.spans)) pick(null);
  $("no-doubt").hidden = s.doubtful.length > 0;
  $("doubtful").replaceChildren(...s.doubtful.slice(0, 30).map((d) => {
    const li = document.createElement("li");
    li.textContent = `id ${d.track}: ` + (d.first === d.last ? `frame ${d.first}` : `frames ${d.first}-${d.last}`);
    li.onclick = () => { pick(d.track); show(d.first); };
    return li;
  }));
  document.body.dataset.version = s.version;
  await show(state.frame);
}

async function post(path, body) {
  $("save-status").textContent = "saving"; $("save-status").className = "busy";
  try {
    const r = await api(path, body);
    showMessage(r.message || `wrote ${r.tracks} (${r.rows} rows) and ${r.log}`, true);
    $("save-status").textContent = "saved"; $("save-status").className = "ok";
    await refresh();
  } catch (e) {
    showMessage(e.message);
    $("save-status").textContent = "saved"; $("save-status").className = "ok";
  }
}

function correct() {
  const kind = $("kind").value, other = parseInt($("other").value, 10);
  document.activeElement.blur();  // the keys go back to the page
  if (state.picked === null) { showMessage("click a box first"); return; }
  const c = { kind, track: state.picked };
  if (["swap", "merge", "assign"].includes(kind)) {
    if (!(other >= 1)) { showMessage(`${kind}: give the other id`); return; }
    c.other = other;
  }
  if (["swap", "split", "assign"].includes(kind)) c.frame = state.frame;
  post("api/correct", c);
}

function nextDoubtful() {
  const d = state.doubtful.filter((x) => x.first > state.frame).sort((a, b) => a.first - b.first)[0]
    || state.doubtful[0];
  if (d) { pick(d.track); show(d.first); }
}

function onClick(ev) {
  const r = $("view").getBoundingClientRect(), s = state.scale;
  const px = (ev.clientX - r.left) / s, py = (ev.clientY - r.top) / s;
  const hits = (state.rows.get(state.frame) || []).filter(([, , x, y, w, h]) =>
    px >= x && px <= x + w && py >= y && py <= y + h);
  hits.sort((a, b) => a[4] * a[5] - b[4] * b[5]);  // the smallest box on top
  pick(hits.length ? hits[0][1] : null);
}

const KINDS = { s: "swap", a: "assign", m: "merge", x: "split", Delete: "delete" };

function onKey(ev) {
  if (["INPUT", "SELECT"].includes(ev.target.tagName) && ev.key !== "Enter") return;
  const steps = { ArrowRight: 1, ArrowLeft: -1, PageDown: 10, PageUp: -10 };
  if (ev.key in steps) show(state.frame + steps[ev.key]);
  else if (ev.key === "Home") show(1);
  else if (ev.key === "End") show(state.meta.n_frames);
  else if (ev.key === "n") nextDoubtful();
  else if (ev.key === "u") post("api/undo", {});
  else if (ev.key in KINDS) { $("kind").value = KINDS[ev.key]; $("other").focus(); }
  else return;
  ev.preventDefault();
}

async function main() {
  state.meta = await api("api/meta");
  const m = state.meta;
  $("video-name").textContent = m.video;
  $("frame-count").textContent = m.n_frames;
  $("mode").textContent = m.propagates ? `closed set of ${m.n_targets}: corrections re-solve it` : "plain edits";
  state.scale = Math.min(1, MAX_WIDTH / m.width, MAX_HEIGHT / m.height) || 1;
  $("view").width = Math.round(m.width * state.scale); $("view").height = Math.round(m.height * state.scale);
  $("view").addEventListener("click", onClick);
  $("timeline").width = $("view").width;
  $("timeline").addEventListener("click", onTimeline);
  $("prev").onclick = () => show(state.frame - 1);
  $("next").onclick = () => show(state.frame + 1);
  $("undo-btn").onclick = () => post("api/undo", {});
  $("export-btn").onclick = () => post("api/export", {});
  $("correct-form").addEventListener("submit", (ev) => { ev.preventDefault(); correct(); });
  document.addEventListener("keydown", onKey);
  const asked = /frame=(\d+)/.exec(location.hash);
  state.frame = asked ? parseInt(asked[1], 10) : 1;
  await refresh();
}

main().catch((e) => showMessage(e.message));

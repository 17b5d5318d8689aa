// The labelling page (plain JavaScript, no build step, no network access beyond this server).
// Label values: agent id 0..N-1, -1 false positive, -2 not labelled yet.
"use strict";

const UNSET = -2, FP = -1, CHUNK = 200, HIT_PX = 16;
const state = {
  meta: null, labels: [], frames: new Map(), pending: new Map(), frame: 0,
  showTruth: false, bench: null, saving: Promise.resolve(), unsaved: 0, screen: [], timer: null,
};

function showMessage(text) { $("message").textContent = text || ""; }

async function chunk(k) {
  const start = Math.floor(k / CHUNK) * CHUNK;
  if (!state.pending.has(start)) {
    state.pending.set(start, api(`api/frames?start=${start}&count=${CHUNK}`).then((d) => {
      for (const f of d.frames) state.frames.set(f.frame, f);
    }));
  }
  await state.pending.get(start);
}

async function getFrame(k) {
  if (!state.frames.has(k)) await chunk(k);
  const next = Math.floor(k / CHUNK) * CHUNK + CHUNK;  // prefetch the following chunk
  if (next < state.meta.n_frames) chunk(next).catch(() => {});
  return state.frames.get(k);
}

function colourOf(label) {
  if (label >= 0) return state.meta.colours[label];
  return label === FP ? state.meta.fp_colour : "#ffffff";
}

function labelName(label) {
  return label >= 0 ? `robot ${label + 1}` : label === FP ? "false positive" : "not labelled";
}

function cycle(label, step) {
  const order = [...Array(state.meta.n_agents).keys(), FP];
  if (label === UNSET) return step > 0 ? order[0] : FP;
  const i = order.indexOf(label);
  return order[(i + step + order.length) % order.length];
}

function geometry(canvas) {
  const R = state.meta.max_range_m, half = Math.min(state.meta.fov_rad / 2, Math.PI / 2);
  const W = canvas.width, H = canvas.height;
  const scale = Math.min((H - 50) / R, (W / 2 - 20) / Math.max(R * Math.sin(half), 1e-6));
  return { cx: W / 2, cy: H - 25, scale, toScreen: (x, y) => [W / 2 - y * scale, H - 25 - x * scale] };
}

// Angles: 0 points up (observer forward), positive turns left, as in the observer frame.
function arrow(ctx, sx, sy, angle, len, colour, width) {
  const ex = sx - Math.sin(angle) * len, ey = sy - Math.cos(angle) * len;
  ctx.strokeStyle = colour; ctx.lineWidth = width;
  ctx.beginPath(); ctx.moveTo(sx, sy); ctx.lineTo(ex, ey); ctx.stroke();
  const a = Math.atan2(ey - sy, ex - sx);
  ctx.beginPath(); ctx.moveTo(ex, ey);
  ctx.lineTo(ex - 7 * Math.cos(a - 0.45), ey - 7 * Math.sin(a - 0.45));
  ctx.lineTo(ex - 7 * Math.cos(a + 0.45), ey - 7 * Math.sin(a + 0.45));
  ctx.closePath(); ctx.fillStyle = colour; ctx.fill();
}

function drawView(f) {
  const canvas = $("view"), ctx = canvas.getContext("2d"), g = geometry(canvas);
  const R = state.meta.max_range_m, half = state.meta.fov_rad / 2;
  ctx.clearRect(0, 0, canvas.width, canvas.height);
  ctx.fillStyle = "rgba(255,255,255,0.10)";
  ctx.beginPath(); ctx.moveTo(g.cx, g.cy);
  ctx.arc(g.cx, g.cy, R * g.scale, -Math.PI / 2 - half, -Math.PI / 2 + half); ctx.closePath(); ctx.fill();
  ctx.strokeStyle = "rgba(255,255,255,0.35)"; ctx.lineWidth = 1; ctx.font = "11px sans-serif";
  ctx.fillStyle = "rgba(255,255,255,0.7)";
  for (let r = 1; r <= R; r += 1) {
    ctx.beginPath(); ctx.arc(g.cx, g.cy, r * g.scale, Math.PI, 2 * Math.PI); ctx.stroke();
    ctx.fillText(`${r} m`, g.cx + 3, g.cy - r * g.scale - 2);
  }
  ctx.fillStyle = "#222"; ctx.beginPath(); ctx.arc(g.cx, g.cy, 6, 0, 2 * Math.PI); ctx.fill();
  const labels = state.labels[f.frame];
  state.screen = [];
  f.detections.forEach((d, j) => {
    const [sx, sy] = g.toScreen(d.x, d.y), lab = labels[j];
    state.screen.push([sx, sy]);
    if (state.showTruth && f.truth) {
      ctx.strokeStyle = colourOf(f.truth[j]); ctx.lineWidth = 4;
      ctx.beginPath(); ctx.arc(sx, sy, 17, 0, 2 * Math.PI); ctx.stroke();
    }
    ctx.fillStyle = colourOf(lab); ctx.strokeStyle = "#111"; ctx.lineWidth = 1.5;
    ctx.setLineDash(lab === UNSET ? [3, 3] : []);
    ctx.beginPath(); ctx.arc(sx, sy, 11, 0, 2 * Math.PI); ctx.fill(); ctx.stroke(); ctx.setLineDash([]);
    if (lab === FP) {
      ctx.strokeStyle = "#444"; ctx.lineWidth = 2; ctx.beginPath();
      ctx.moveTo(sx - 6, sy - 6); ctx.lineTo(sx + 6, sy + 6); ctx.moveTo(sx + 6, sy - 6); ctx.lineTo(sx - 6, sy + 6);
      ctx.stroke();
    }
    arrow(ctx, sx, sy, d.heading, 30, "#111", 2);
    ctx.fillStyle = "#fff"; ctx.font = "12px sans-serif";
    ctx.fillText(`#${j + 1} ${d.score.toFixed(2)}`, sx + 14, sy + 14);
  });
}

function drawRobots(f) {
  const box = $("robots"); box.textContent = "";
  const latest = new Map(f.reports.map((r) => [r.agent, r]));
  for (let i = 0; i < state.meta.n_agents; i++) {
    const row = document.createElement("div"); row.className = "robot";
    const c = document.createElement("canvas"); c.width = 44; c.height = 44;
    const ctx = c.getContext("2d");
    ctx.fillStyle = state.meta.colours[i]; ctx.beginPath(); ctx.arc(22, 22, 20, 0, 2 * Math.PI); ctx.fill();
    const r = latest.get(i);
    if (r) arrow(ctx, 22, 22, r.heading, 18, "#111", 2);
    const text = document.createElement("span");
    text.textContent = r ? `robot ${i + 1}: ${(r.heading * 180 / Math.PI).toFixed(0)}°, ${r.age.toFixed(2)} s old`
      : `robot ${i + 1}: no report yet`;
    row.append(c, text); box.append(row);
  }
}

function drawTable(f) {
  const body = $("detections").querySelector("tbody"); body.textContent = "";
  const labels = state.labels[f.frame];
  f.detections.forEach((d, j) => {
    const tr = document.createElement("tr");
    tr.dataset.det = j; tr.dataset.label = labels[j];
    tr.dataset.sx = state.screen[j][0].toFixed(1); tr.dataset.sy = state.screen[j][1].toFixed(1);
    const sw = `<span class="swatch" style="background:${colourOf(labels[j])}"></span>`;
    tr.innerHTML = `<td>${j + 1}</td><td>${sw} ${labelName(labels[j])}</td><td>${d.score.toFixed(2)}</td>` +
      `<td>${d.x.toFixed(2)}, ${d.y.toFixed(2)}</td><td>${(d.heading * 180 / Math.PI).toFixed(0)}°</td>`;
    body.append(tr);
  });
}

async function render() {
  const k = state.frame, f = await getFrame(k);
  if (k !== state.frame || !f) return;  // the user moved on meanwhile
  $("frame-index").textContent = k + 1;
  $("frame-time").textContent = `${f.time.toFixed(2)} s`;
  drawView(f); drawRobots(f); drawTable(f);
  const img = $("frame-image");
  if (state.meta.image_pattern) {
    img.src = state.meta.image_pattern.replace("{frame:06d}", String(k + 1).padStart(6, "0"));
    img.hidden = false;
  }
  document.body.dataset.frame = k;
}

function goTo(k) {
  state.frame = Math.max(0, Math.min(state.meta.n_frames - 1, k));
  history.replaceState(null, "", `#frame=${state.frame + 1}`);
  render().catch((e) => showMessage(e.message));
}

function locked() {
  const b = state.bench;
  if (!state.meta.benchmark) return false;
  return !b || b.finished_at !== null;
}

function setSaveStatus() {
  const s = $("save-status");
  if (s.classList.contains("fail")) return;
  s.className = state.unsaved ? "busy" : "ok";
  s.textContent = state.unsaved ? `saving ${state.unsaved}…` : "saved";
}

function setLabel(k, j, label) {
  state.labels[k][j] = label;
  state.unsaved += 1; setSaveStatus();
  state.saving = state.saving.then(() => api("api/label", { frame: k, detection: j, label }))
    .then(() => { state.unsaved -= 1; setSaveStatus(); })
    .catch((e) => {
      state.unsaved -= 1;
      const s = $("save-status"); s.className = "fail"; s.textContent = "NOT SAVED";
      showMessage(`saving failed: ${e.message}`);
    });
  render();
}

function onClick(ev, step) {
  ev.preventDefault();
  if (locked()) { showMessage(state.bench ? "the session has finished" : "press start first"); return; }
  const rect = ev.target.getBoundingClientRect();
  const x = (ev.clientX - rect.left) * (ev.target.width / rect.width);
  const y = (ev.clientY - rect.top) * (ev.target.height / rect.height);
  let best = -1, bestD = HIT_PX;
  state.screen.forEach(([sx, sy], j) => {
    const d = Math.hypot(sx - x, sy - y);
    if (d <= bestD) { best = j; bestD = d; }
  });
  if (best < 0) return;
  const k = state.frame;
  setLabel(k, best, cycle(state.labels[k][best], step));
}

function nextUnlabelled() {
  for (let k = state.frame + 1; k < state.meta.n_frames; k++) {
    if (state.labels[k].includes(UNSET)) { goTo(k); return; }
  }
  showMessage("no unlabelled detection after this frame");
}

function onKey(ev) {
  if (ev.target.tagName === "INPUT" && ev.target.type !== "checkbox") return;
  const k = state.frame;
  const keys = {
    ArrowRight: () => goTo(k + 1), d: () => goTo(k + 1), " ": () => goTo(k + 1),
    ArrowLeft: () => goTo(k - 1), a: () => goTo(k - 1),
    PageDown: () => goTo(k + 10), PageUp: () => goTo(k - 10),
    Home: () => goTo(0), End: () => goTo(state.meta.n_frames - 1), n: nextUnlabelled,
    t: () => { if (state.meta.has_truth) { $("show-truth").checked = !state.showTruth; toggleTruth(); } },
  };
  const fn = keys[ev.key];
  if (fn) { ev.preventDefault(); fn(); }
}

function toggleTruth() { state.showTruth = $("show-truth").checked; render(); }

function pct(x) { return x === null || x === undefined ? "–" : `${(100 * x).toFixed(1)}%`; }

function showResult(r, title) {
  const box = $("result"); box.hidden = false;
  const time = r.duration_s !== undefined ? `<br>time: <b id="result-time">${r.duration_s.toFixed(1)} s</b>` : "";
  box.innerHTML = `<b>${title}</b><br>success rate: <b id="result-rate">${pct(r.success_rate)}</b>` +
    ` over ${r.frames_scored} frames (${r.correct} of ${r.detections_scored} detections right,` +
    ` ${r.unset} not labelled)<br>whole sequence: ${pct(r.success_rate_all)}${time}`;
  box.dataset.rate = r.success_rate === null ? "" : r.success_rate;
}

function updateBenchUi() {
  const b = state.bench, running = b && b.finished_at === null;
  $("start-btn").hidden = !!b; $("finish-btn").hidden = !running;
  clearInterval(state.timer);
  if (running) {
    const tick = () => { $("timer").textContent = `${(Date.now() / 1000 - b.started_at).toFixed(0)} s`; };
    tick(); state.timer = setInterval(tick, 1000);
  } else if (b) {
    $("timer").textContent = ""; showResult(b, "Benchmark finished");
  }
}

async function init() {
  state.meta = await api("api/meta");
  const m = state.meta;
  $("seq-name").textContent = m.name; $("frame-count").textContent = m.n_frames;
  $("mode").textContent = m.benchmark ? "human benchmark (truth hidden)" : `labels from: ${m.source}`;
  const saved = await api("api/labels");
  state.labels = saved.labels; state.bench = saved.benchmark;
  if (m.has_truth) { $("truth-toggle").hidden = false; $("score-btn").hidden = false; }
  if (m.benchmark) updateBenchUi();
  const canvas = $("view");
  canvas.addEventListener("click", (e) => onClick(e, +1));
  canvas.addEventListener("contextmenu", (e) => onClick(e, -1));
  document.addEventListener("keydown", onKey);
  $("prev").onclick = () => goTo(state.frame - 1);
  $("next").onclick = () => goTo(state.frame + 1);
  $("show-truth").onchange = toggleTruth;
  $("score-btn").onclick = async () => {
    await state.saving; showResult(await api("api/score"), "Labels against the truth");
  };
  $("start-btn").onclick = async () => {
    state.bench = (await api("api/benchmark/start", {})).benchmark; updateBenchUi();
  };
  $("finish-btn").onclick = async () => {
    await state.saving;
    state.bench = (await api("api/benchmark/finish", {})).benchmark; updateBenchUi(); render();
  };
  $("export-btn").onclick = async () => {
    await state.saving;
    const r = await api("api/export", {});
    showMessage(`wrote ${r.truth} and ${r.mot} (${r.mot_rows} rows, ${r.unset} detections not labelled)`);
  };
  window.addEventListener("beforeunload", (e) => { if (state.unsaved) e.preventDefault(); });
  const hash = /frame=(\d+)/.exec(location.hash);
  goTo(hash ? parseInt(hash[1], 10) - 1 : 0);
  document.body.dataset.ready = "1";
}

init().catch((e) => showMessage(`could not start: ${e.message}`));

// The explorer page: pose inputs -> the wasm evaluator (needle-wasm.mjs) -> the six
// components, their status, the force-depth curve of the pose with the set's FE points
// when the pose is one of its runs, and side views of needle and block.
// Served by `needle explore` (crates/explore); no network, no framework.
import { load, COMPONENTS, FE_UNSOLVED, statusNames } from "./needle-wasm.mjs";

// a component's unit from its name: "_n" newtons, "_nmm" newton millimetres
const UNITS = Object.fromEntries(COMPONENTS.map((c) => [c, c.endsWith("_nmm") ? "N·mm" : "N"]));
const CURVE_POINTS = 61; // depths 0 .. depth_max for the plot and the CSV
const $ = (id) => document.getElementById(id);

const [model, set, files] = await Promise.all([
  fetch("needle.wasm").then((r) => r.arrayBuffer()).then(load),
  fetch("set.json").then((r) => r.json()),
  fetch("stacks.json").then((r) => r.json()),
]);
const d = model.domain;
const INPUTS = [
  { name: "x_mm", flag: "--x-mm", label: "x (mm)", min: -d.x_max_mm, max: d.x_max_mm, step: 0.01 },
  { name: "z_mm", flag: "--z-mm", label: "z (mm)", min: -d.z_max_mm, max: d.z_max_mm, step: 0.01 },
  { name: "theta_x_deg", flag: "--theta-x-deg", label: "θx (deg)", min: -d.theta_max_deg, max: d.theta_max_deg, step: 0.01 },
  { name: "theta_z_deg", flag: "--theta-z-deg", label: "θz (deg)", min: -d.theta_max_deg, max: d.theta_max_deg, step: 0.01 },
  { name: "depth_mm", flag: "--depth-mm", label: "depth (mm)", min: 0, max: d.depth_max_mm, step: 0.01 },
];

$("about").textContent =
  `set ${set.set} (${set.set_arg}), ${model.form} model, domain |x|, |z| ≤ ${d.x_max_mm} mm, ` +
  `|θ| ≤ ${d.theta_max_deg}°, depth 0 .. ${d.depth_max_mm} mm; ${set.runs.length} FE runs. ` +
  "Evaluated in your browser by the firmware's own f32 code (wasm).";

// inputs: a slider (inside the domain) and a number field (any value: the evaluator
// clamps it to the domain and raises the saturation flag, shown in the status)
const pose = { x_mm: 0, z_mm: 0, theta_x_deg: 0, theta_z_deg: 0, depth_mm: d.depth_max_mm / 2 };
for (const inp of INPUTS) {
  const row = document.createElement("div");
  row.className = "row";
  row.innerHTML =
    `<label for="${inp.name}-num">${inp.label}</label>` +
    `<input type="range" id="${inp.name}-range" min="${inp.min}" max="${inp.max}" step="${inp.step}" aria-label="${inp.label} slider">` +
    `<input type="number" id="${inp.name}-num" step="${inp.step}">`;
  $("inputs").appendChild(row);
  const range = row.querySelector("input[type=range]");
  const num = row.querySelector("input[type=number]");
  range.value = num.value = pose[inp.name];
  range.addEventListener("input", () => { num.value = range.value; set_value(inp.name, Number(range.value)); });
  num.addEventListener("input", () => {
    const v = Number(num.value);
    if (num.value.trim() === "" || !Number.isFinite(v)) return; // half-typed: keep the last pose
    range.value = Math.min(inp.max, Math.max(inp.min, v));
    set_value(inp.name, v);
  });
}
for (const c of COMPONENTS) {
  const tr = document.createElement("tr");
  tr.innerHTML = `<td>${c}</td><td class="value" id="w-${c}"></td><td>${UNITS[c]}</td>`;
  $("wrench").appendChild(tr);
  const o = document.createElement("option");
  o.value = o.textContent = c;
  $("component").appendChild(o);
}
$("component").value = "fy_n";
$("component").addEventListener("change", update);

function set_value(name, v) {
  pose[name] = v;
  update();
}

const evalAt = (depth) => model.evaluate(pose.x_mm, pose.z_mm, pose.theta_x_deg, pose.theta_z_deg, depth);

function curve() {
  const out = [];
  for (let i = 0; i < CURVE_POINTS; i++) {
    const depth = (d.depth_max_mm * i) / (CURVE_POINTS - 1);
    out.push({ depth, ...evalAt(depth) });
  }
  return out;
}

// the FE run at this pose, if any (set poses are given to 0.01 mm / 0.01 degree)
function feRun() {
  const same = (a, b) => Math.abs(a - b) < 1e-6;
  return set.runs.find((r) => same(r.x_mm, pose.x_mm) && same(r.z_mm, pose.z_mm) &&
    same(r.theta_x_deg, pose.theta_x_deg) && same(r.theta_z_deg, pose.theta_z_deg));
}

function update() {
  const e = evalAt(pose.depth_mm);
  COMPONENTS.forEach((c, k) => {
    const cell = $(`w-${c}`);
    cell.textContent = e.wrench[k].toPrecision(9);
    cell.dataset.bits = "0x" + e.bits[k].toString(16).padStart(8, "0");
  });
  const st = $("status");
  st.textContent = `${statusNames(e.status)} (0x${e.status.toString(16).padStart(2, "0")})`;
  st.dataset.bits = String(e.status);
  st.className = e.status & 0x80 ? "error" : e.status & 0x1f ? "saturated" : e.status & FE_UNSOLVED ? "unsolved" : "";
  $("unsolved-note").hidden = !(e.status & FE_UNSOLVED);
  const args = INPUTS.map((i) => `${i.flag} ${pose[i.name]}`).join(" ");
  $("command").textContent = `needle eval --set ${set.set_arg} ${args}`;
  const pts = curve();
  const csv = ["depth_mm," + COMPONENTS.join(",") + ",status"]
    .concat(pts.map((p) => [p.depth, ...Array.from(p.wrench, (v) => v.toPrecision(9)), p.status].join(",")))
    .join("\n") + "\n";
  $("csv").href = "data:text/csv;charset=utf-8," + encodeURIComponent(csv);
  drawPlot(pts, feRun());
  drawSide();
}

$("copy").addEventListener("click", async () => {
  try {
    await navigator.clipboard.writeText($("command").textContent);
    $("copy").textContent = "copied";
  } catch {
    $("copy").textContent = "copy failed: select the command below";
  }
  setTimeout(() => ($("copy").textContent = "copy as command"), 1500);
});

const tick = (v) => (v !== 0 && Math.abs(v) < 1e-2 ? v.toExponential(1) : v.toPrecision(3));

function drawPlot(pts, run) {
  const canvas = $("plot");
  const g = canvas.getContext("2d");
  const k = COMPONENTS.indexOf($("component").value);
  const W = canvas.width, H = canvas.height, L = 78, R = 15, T = 15, B = 40;
  const ys = pts.map((p) => p.wrench[k]);
  const fe = run ? run.depth_mm.map((dep, i) => [dep, run.wrench[i][k]]) : [];
  let lo = Math.min(0, ...ys, ...fe.map((p) => p[1]));
  let hi = Math.max(0, ...ys, ...fe.map((p) => p[1]));
  if (hi - lo < 1e-12) { hi += 1; lo -= 1; }
  const X = (v) => L + ((W - L - R) * v) / d.depth_max_mm;
  const Y = (v) => T + ((H - T - B) * (hi - v)) / (hi - lo);
  g.clearRect(0, 0, W, H);
  g.strokeStyle = "#888"; g.fillStyle = "#222"; g.font = "12px sans-serif"; g.lineWidth = 1;
  g.beginPath(); g.moveTo(L, T); g.lineTo(L, H - B); g.lineTo(W - R, H - B); g.stroke();
  for (let i = 0; i <= 4; i++) {
    const v = lo + ((hi - lo) * i) / 4;
    g.fillText(tick(v), L - 6 - g.measureText(tick(v)).width, Y(v) + 4);
    const dep = (d.depth_max_mm * i) / 4;
    g.fillText(dep.toFixed(1), X(dep) - 8, H - B + 16);
  }
  g.fillText(`depth (mm)`, W / 2 - 30, H - 6);
  g.save(); g.translate(12, H / 2 + 40); g.rotate(-Math.PI / 2);
  g.fillText(`${COMPONENTS[k]} (${UNITS[COMPONENTS[k]]})`, 0, 0); g.restore();
  g.strokeStyle = "#1f5fbf"; g.lineWidth = 2; g.beginPath();
  pts.forEach((p, i) => (i ? g.lineTo : g.moveTo).call(g, X(p.depth), Y(p.wrench[k])));
  g.stroke();
  // the depths where the pose is in the unsolved region (FE_UNSOLVED): drawn over, dashed
  g.strokeStyle = "#e67e22"; g.lineWidth = 4; g.setLineDash([6, 4]); g.beginPath();
  pts.forEach((p, i) => {
    const prev = pts[i - 1];
    if (prev && p.status & FE_UNSOLVED && prev.status & FE_UNSOLVED) {
      g.moveTo(X(prev.depth), Y(prev.wrench[k])); g.lineTo(X(p.depth), Y(p.wrench[k]));
    }
  });
  g.stroke(); g.setLineDash([]);
  const unsolved = pts.some((p) => p.status & FE_UNSOLVED);
  g.fillStyle = "#c0392b";
  for (const [dep, v] of fe) { g.beginPath(); g.arc(X(dep), Y(v), 3.5, 0, 2 * Math.PI); g.fill(); }
  g.strokeStyle = "#aaa"; g.lineWidth = 1; g.setLineDash([4, 4]);
  g.beginPath(); g.moveTo(X(pose.depth_mm), T); g.lineTo(X(pose.depth_mm), H - B); g.stroke(); g.setLineDash([]);
  $("fe-note").textContent = (run
    ? `line: model; dots: FE run ${run.name} (${run.role}) of the set at this pose`
    : "line: model (no FE run of the set at this pose: set a run's pose to overlay its points)") +
    (unsolved ? "; dashed orange: FE_UNSOLVED, where the FE could not solve (the model extrapolates)" : "");
}

// two views of block (grey) and needle (dark): left looking along -z (x right, y up),
// right looking along +x (z right, y up); the needle's axis from the library's frame
function drawSide() {
  const rad = Math.PI / 180;
  const [sx, cx] = [Math.sin(pose.theta_x_deg * rad), Math.cos(pose.theta_x_deg * rad)];
  const [sz, cz] = [Math.sin(pose.theta_z_deg * rad), Math.cos(pose.theta_z_deg * rad)];
  const axis = [-sz * cx, cz * cx, sx]; // tip -> hub, unit
  const dep = Math.min(Math.max(pose.depth_mm, 0), d.depth_max_mm);
  const tip = [pose.x_mm - dep * axis[0], -dep * axis[1], pose.z_mm - dep * axis[2]];
  const len = 20; // mm of needle drawn
  const hub = tip.map((v, i) => v + len * axis[i]);
  const b = set.block, s = 260 / Math.max(b.size_x_mm, b.size_z_mm, 1);
  const views = [
    { ox: 10, h: 0, w: b.size_x_mm, title: "front (x →)" },
    { ox: 290, h: 2, w: b.size_z_mm, title: "side (z →)" },
  ];
  let svg = "";
  for (const v of views) {
    const X = (p) => v.ox + (p + v.w / 2) * s;
    const Y = (y) => 20 + (len - y) * s;
    svg += `<text x="${v.ox}" y="14" font-size="12">${v.title}, 1 mm = ${s.toFixed(1)} px</text>`;
    svg += `<rect x="${X(-v.w / 2)}" y="${Y(0)}" width="${v.w * s}" height="${Math.min(b.depth_mm * s, 200)}" fill="#e8d9cf" stroke="#999"/>`;
    svg += `<line x1="${X(tip[v.h])}" y1="${Y(tip[1])}" x2="${X(hub[v.h])}" y2="${Y(hub[1])}" stroke="#333" stroke-width="${Math.max(set.needle.diameter_mm * s, 1.5)}"/>`;
  }
  $("side").innerHTML = svg;
}

update();
document.body.dataset.ready = "yes";

// The insertion player: the firmware's insertion model (wasm) through a compiled-in
// stack, at 1 kHz: in at the chosen speed, stopped for a while on the way (to show the
// viscoelastic relaxation: the needle still, the force falling), on to 5 mm past the
// layers and back out. Depths are f64 steps of speed * 1 ms from -1 mm, passed as f32
// (crates/cli/tests/explore_browser.rs replays the same script through the library).

// "g:tau_s, g:tau_s" -> [{ g, tau_s }], [] for an empty field; null for text that is not
// numbers (the module refuses out-of-range terms itself)
function parseProny(text) {
  if (!text.trim()) return [];
  const terms = text.split(",").map((t) => t.split(":").map(Number));
  if (terms.some((t) => t.length !== 2 || !t.every(Number.isFinite))) return null;
  return terms.map(([g, tau_s]) => ({ g, tau_s }));
}

// the script's depths: in to `stop_mm` (or to the end when null), held for `hold_ticks`
// ticks at the last depth reached, on to `deepest`, back out to -1 mm
function script(step, deepest, stop_mm, hold_ticks) {
  const depths = [];
  let dep = -1;
  if (stop_mm !== null) {
    for (; dep < stop_mm; dep += step) depths.push(dep);
    const held = depths.length ? depths[depths.length - 1] : -1;
    for (let i = 0; i < hold_ticks; i++) depths.push(held);
  }
  for (; dep < deepest; dep += step) depths.push(dep);
  for (dep = deepest; dep > -1; dep -= step) depths.push(dep);
  return depths;
}

// the chosen stack: "c:i" the compiled-in stack i; "f:j" tissue file j of /stacks.json,
// "f:j:k" its draw k (needle explore --stack): { thickness_mm, run(poses, terms), values }
function chosenStack() {
  const [kind, j, k] = $("stack").value.split(":");
  if (kind === "c") {
    const s = Number(j);
    const st = model.stacks[s];
    return st && { thickness_mm: st.thickness_mm, run: (poses, terms) => model.insert(s, poses, terms), values: [] };
  }
  const file = files[Number(j)];
  const drawn = k === undefined ? null : file?.drawn[Number(k)];
  const st = drawn ? drawn.stack : file?.stack;
  return st && { thickness_mm: st.thickness_mm, run: (poses) => model.insertLayers(st, poses), values: drawn ? drawn.values : [], file: true };
}

function playInsertion() {
  const stack = chosenStack();
  if (!stack) return;
  const total = stack.thickness_mm.reduce((a, b) => a + b, 0);
  const deepest = total + 5;
  const speed = Math.max(0.1, Number($("speed").value) || 3);
  const step = speed * 0.001;
  const prony = parseProny($("prony").value);
  if (prony === null) { $("insertion-summary").textContent = "Prony terms: write g:tau_s pairs, e.g. 0.6:0.5, 0.4:5"; return; }
  const terms = prony.length ? prony : null;
  const at = (depth_mm) => ({ ...pose, depth_mm });
  let ticks;
  let stop = $("stop").value.trim() === "" ? null : Number($("stop").value);
  const hold_ticks = Math.max(0, Math.round(1000 * (Number($("hold").value) || 0)));
  try {
    if (stop === null) {
      // stop at 80 % of the depth of the first puncture of the same insertion unstopped
      const dry = stack.run(script(step, deepest, null, 0).map(at), terms);
      const first = dry.findIndex((t) => t.punctures > 0);
      stop = first > 0 ? 0.8 * dry[first].depth_mm : null;
    }
    ticks = stack.run(script(step, deepest, stop, hold_ticks).map(at), terms);
  } catch (err) {
    $("insertion-summary").textContent = String(err.message);
    return;
  }
  const punctures = ticks.filter((t) => t.punctures > 0);
  const holdStart = stop === null ? -1 : ticks.findIndex((t, i) => i > 0 && t.depth_mm === ticks[i - 1].depth_mm);
  const held = holdStart > 0 && hold_ticks > 0 ? [ticks[holdStart - 1], ticks[holdStart + hold_ticks - 1]] : null;
  const relax = held
    ? `; stopped at ${held[0].depth_mm.toFixed(2)} mm for ${(hold_ticks / 1000).toFixed(1)} s: Fy ${held[0].fy_n.toPrecision(3)} -> ${held[1].fy_n.toPrecision(3)} N` +
      (held[0].fy_n !== 0 ? ` (${(100 * (held[1].fy_n / held[0].fy_n - 1)).toFixed(1)} %)` : "")
    : "";
  // a drawn tissue: each drawn value beside the file's (needle stack sample's draw)
  const drawnText = stack.values.map((v) => `layer ${v.layer} ${v.key} ${v.from.toPrecision(4)} -> ${v.to.toPrecision(4)}`).join("; ");
  const own = stack.file ? "; the file's own Prony terms" : "";
  $("insertion-summary").textContent = `${ticks.length} ticks, ${punctures.length} puncture(s), largest Fy ${Math.max(...ticks.map((t) => t.fy_n)).toPrecision(3)} N${relax}${own}` +
    (drawnText ? `. Drawn: ${drawnText}` : "");
  if (held) {
    document.body.dataset.holdFyStart = String(held[0].fy_n);
    document.body.dataset.holdFyEnd = String(held[1].fy_n);
  }
  document.body.dataset.insertionPunctures = String(punctures.reduce((a, t) => a + t.punctures, 0));
  const canvas = $("insertion");
  const g = canvas.getContext("2d");
  const W = canvas.width, H = canvas.height, L = 60, R = 15, T = 15, B = 40;
  const fy = ticks.map((t) => t.fy_n);
  const end_s = ticks.length / 1000;
  let lo = Math.min(0, ...fy), hi = Math.max(0, ...fy);
  if (hi - lo < 1e-12) { hi += 1; lo -= 1; }
  const X = (t_s) => L + ((W - L - R) * t_s) / end_s;
  const Y = (v) => T + ((H - T - B) * (hi - v)) / (hi - lo);
  g.clearRect(0, 0, W, H);
  if (held) {
    g.fillStyle = "#eef3fb";
    g.fillRect(X(holdStart / 1000), T, X((holdStart + hold_ticks) / 1000) - X(holdStart / 1000), H - T - B);
  }
  g.strokeStyle = "#888"; g.fillStyle = "#222"; g.font = "12px sans-serif"; g.lineWidth = 1;
  g.beginPath(); g.moveTo(L, T); g.lineTo(L, H - B); g.lineTo(W - R, H - B); g.stroke();
  for (let i = 0; i <= 4; i++) {
    const v = lo + ((hi - lo) * i) / 4;
    g.fillText(tick(v), L - 6 - g.measureText(tick(v)).width, Y(v) + 4);
    const t_s = (end_s * i) / 4;
    g.fillText(t_s.toFixed(1), X(t_s) - 8, H - B + 16);
  }
  g.fillText("time (s)", W / 2 - 20, H - 6);
  g.strokeStyle = "#1f5fbf"; g.lineWidth = 1.5; g.beginPath();
  ticks.forEach((t, i) => (i ? g.lineTo : g.moveTo).call(g, X(i / 1000), Y(t.fy_n)));
  g.stroke();
  g.fillStyle = "#c0392b";
  ticks.forEach((t, i) => {
    if (t.punctures > 0 && i > 0) { g.beginPath(); g.arc(X((i - 1) / 1000), Y(ticks[i - 1].fy_n), 4, 0, 2 * Math.PI); g.fill(); }
  });
}
if (set.viscoelastic) {
  $("prony").value = set.viscoelastic.g.map((g, i) => `${g}:${set.viscoelastic.tau_s[i]}`).join(", ");
}
const option = (value, text) => {
  const o = document.createElement("option");
  o.value = value;
  o.textContent = text;
  $("stack").appendChild(o);
};
model.stacks.forEach((st, i) => option(`c:${i}`, `${st.name} (${st.thickness_mm.length} layers)`));
files.forEach((f, j) => {
  option(`f:${j}`, `${f.name} (file ${f.file}, ${f.stack.thickness_mm.length} layers)`);
  f.drawn.forEach((d, k) => option(`f:${j}:${k}`, `${f.name} drawn within its spread, seed ${d.seed}`));
});
if (model.stacks.length === 0 && files.length === 0) $("insertion-section").hidden = true;
$("play").addEventListener("click", playInsertion);

// Plays tissue files and the tissues drawn within their spread (/stacks.json of `needle
// explore --stack`) through the page's glue (needle-wasm.mjs insertLayers) and prints,
// per stack, the ticks, the punctures and an FNV-1a digest of every tick's Fy bits,
// phase code and punctures.
// Usage: node stack_files.mjs NEEDLE_WASM STACKS_JSON DEPTHS_JSON (DEPTHS_JSON: the
// path's depths in mm, f32 values, the centred vertical needle).
// Run by crates/cli/tests/explore_stack_files.rs.
import { readFileSync } from "node:fs";
import { load } from "../../../crates/explore/src/page/needle-wasm.mjs";

const [wasmPath, stacksPath, depthsPath] = process.argv.slice(2);
if (!wasmPath || !stacksPath || !depthsPath) {
  console.error("usage: node stack_files.mjs NEEDLE_WASM STACKS_JSON DEPTHS_JSON");
  process.exit(2);
}
const model = await load(readFileSync(wasmPath));
const files = JSON.parse(readFileSync(stacksPath, "utf8"));
const poses = JSON.parse(readFileSync(depthsPath, "utf8")).map((depth_mm) => ({ x_mm: 0, z_mm: 0, theta_x_deg: 0, theta_z_deg: 0, depth_mm }));
const MASK = (1n << 64n) - 1n;
const word = (d, v) => {
  for (let b = 0; b < 4; b++) {
    d ^= BigInt((v >>> (8 * b)) & 0xff);
    d = (d * 0x100000001b3n) & MASK;
  }
  return d;
};
const play = (label, stack) => {
  let digest = 0xcbf29ce484222325n, punctures = 0;
  const ticks = model.insertLayers(stack, poses);
  for (const t of ticks) {
    digest = word(digest, new Uint32Array(Float32Array.of(t.fy_n).buffer)[0]);
    digest = word(digest, t.phase);
    digest = word(digest, t.punctures);
    punctures += t.punctures;
  }
  console.log(`${label} ticks=${ticks.length} punctures=${punctures} digest=${digest.toString(16).padStart(16, "0")}`);
};
for (const f of files) {
  play(`${f.name} file`, f.stack);
  for (const d of f.drawn) play(`${f.name} seed=${d.seed}`, d.stack);
}

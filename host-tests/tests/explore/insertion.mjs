// Steps the golden insertion paths through the wasm module's insertion exports and prints,
// per path, the line the firmware prints (ticks, punctures, FNV-1a digest of every tick's
// six wrench bits, status, phase code, punctures and the step's flags).
// Usage: node insertion.mjs NEEDLE_WASM POSES  (POSES: lines "stack path x z tx tz depth",
// the five inputs as f32 bits in hex, in tick order; or, with NEEDLE_FIXED=1, as Q16.16
// integers in hex (i32 bits) for the fixed-point insertion, whose lines start "fixed ").
// Run by host-tests/tests/insertion_golden.rs.
import { readFileSync } from "node:fs";

const [wasmPath, posesPath] = process.argv.slice(2);
if (!wasmPath || !posesPath) {
  console.error("usage: node insertion.mjs NEEDLE_WASM POSES");
  process.exit(2);
}
const { instance } = await WebAssembly.instantiate(readFileSync(wasmPath), {});
const w = instance.exports;
const f32 = (hex) => new Float32Array(Uint32Array.of(Number.parseInt(hex, 16)).buffer)[0];
const MASK = (1n << 64n) - 1n;
const word = (d, v) => {
  for (let b = 0; b < 4; b++) {
    d ^= BigInt((v >>> (8 * b)) & 0xff);
    d = (d * 0x100000001b3n) & MASK;
  }
  return d;
};
const hex8 = (v) => "0x" + v.toString(16).padStart(8, "0");
const names = process.env.NEEDLE_STACK_NAMES.split(",");
const fixed = process.env.NEEDLE_FIXED === "1";
const i32 = (hex) => Number.parseInt(hex, 16) | 0;
let current = null;
let digest = 0n, ticks = 0, punctures = 0;
const finish = () => {
  if (current === null) return;
  const [s, p] = current;
  console.log(`${fixed ? "fixed " : ""}stack=${names[s]} path=${p} ticks=${ticks} punctures=${punctures} digest_hi=${hex8(Number(digest >> 32n))} digest_lo=${hex8(Number(digest & 0xffffffffn))}`);
};
for (const line of readFileSync(posesPath, "utf8").split("\n")) {
  if (!line.trim()) continue;
  const [s, p, ...bits] = line.split(" ");
  const key = `${s} ${p}`;
  if (current === null || `${current[0]} ${current[1]}` !== key) {
    finish();
    current = [Number(s), Number(p)];
    digest = 0xcbf29ce484222325n; ticks = 0; punctures = 0;
    const started = fixed ? w.needle_fixed_insertion_start(Number(s), 1000, 5000) : w.needle_insertion_start(Number(s), 0.001, 0.005);
    if (started !== 0) { console.error(`stack ${s}: start failed`); process.exit(2); }
  }
  const r = (fixed ? w.needle_fixed_insertion_step(...bits.map(i32)) : w.needle_insertion_step(...bits.map(f32))) >>> 0;
  const out = new Uint32Array(w.memory.buffer, w.needle_out(), 6);
  for (const v of out) digest = word(digest, v);
  digest = word(digest, r & 0xff);
  digest = word(digest, (r >>> 8) & 0xffff);
  digest = word(digest, (r >>> 24) & 0xf);
  digest = word(digest, r >>> 28);
  ticks++;
  punctures += (r >>> 24) & 0xf;
}
finish();

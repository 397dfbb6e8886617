// Replays a golden-f32.csv (inputs and expected outputs as f32 bit patterns) through the
// wasm evaluator and reports every row whose status or wrench bits differ.
// Usage: node golden.mjs NEEDLE_WASM GOLDEN_CSV   (exit 0: all rows equal; 1: a mismatch;
// 2: bad input). Run by host-tests/tests/explore_wasm.rs.
import { readFileSync } from "node:fs";
import { load } from "../../../crates/explore/src/page/needle-wasm.mjs";

const [wasmPath, csvPath] = process.argv.slice(2);
if (!wasmPath || !csvPath) {
  console.error("usage: node golden.mjs NEEDLE_WASM GOLDEN_CSV");
  process.exit(2);
}
const model = await load(readFileSync(wasmPath));
const lines = readFileSync(csvPath, "utf8").split("\n");
const f32 = (hex) => new Float32Array(Uint32Array.of(Number.parseInt(hex, 16)).buffer)[0];
let rows = 0;
let bad = 0;
for (let i = 1; i < lines.length; i++) {
  const line = lines[i].trim();
  if (!line) continue;
  const cells = line.split(",");
  if (cells.length !== 12 || cells.some((c) => !/^0x[0-9a-f]+$/i.test(c))) {
    console.error(`${csvPath}:${i + 1}: expected 12 hex cells, got ${JSON.stringify(line)}`);
    process.exit(2);
  }
  const input = cells.slice(0, 5).map(f32);
  const want = cells.slice(5).map((c) => Number.parseInt(c, 16) >>> 0);
  const got = model.evaluate(...input);
  const have = [got.status, ...got.bits];
  rows++;
  if (have.some((v, k) => v !== want[k])) {
    bad++;
    if (bad <= 10) {
      const hex = (v) => "0x" + v.toString(16).padStart(8, "0");
      console.error(`${csvPath}:${i + 1}: want ${want.map(hex).join(",")} got ${have.map(hex).join(",")}`);
    }
  }
}
console.log(`${rows} rows, ${bad} differ (form ${model.form})`);
process.exit(bad === 0 && rows > 0 ? 0 : 1);

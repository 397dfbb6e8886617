// The needle-haptics f32 evaluator (crates/wasm, the firmware's own no_std source)
// as a JavaScript object. Shared by the explorer page and the Node golden check
// (host-tests/tests/explore/golden.mjs), so both run the same glue.
//
// load(bytes) -> { evaluate(x_mm, z_mm, theta_x_deg, theta_z_deg, depth_mm),
//                  domain: { x_max_mm, z_max_mm, theta_max_deg, depth_max_mm },
//                  form: "paper" | "coupled" | "unfitted" }
// evaluate returns { status, bits: Uint32Array(n), wrench: Float32Array(n) }, n =
// COMPONENTS.length: fx, fy, fz in N, mx, my, mz in N*mm about the hub, status the
// library's Status bits. COMPONENTS and STATUS_FLAGS are the contract's (needle-contract:
// COMPONENTS, status::NAMES), checked by host-tests/tests/component_names.rs; load()
// refuses a module whose component count differs.

export const COMPONENTS = ["fx_n", "fy_n", "fz_n", "mx_nmm", "my_nmm", "mz_nmm"];

export const STATUS_FLAGS = [
  [0x01, "SAT_X"], [0x02, "SAT_Z"], [0x04, "SAT_THETA_X"], [0x08, "SAT_THETA_Z"],
  [0x10, "SAT_DEPTH"], [0x20, "FE_UNSOLVED"], [0x40, "NO_MODEL"], [0x80, "ERROR"],
];

// FE_UNSOLVED: the pose lies where the set's FE campaign could not solve (its
// unsolved.toml); the wrench is still the model's (an extrapolation), not zeroed.
export const FE_UNSOLVED = 0x20;

export function statusNames(status) {
  const names = STATUS_FLAGS.filter(([bit]) => status & bit).map(([, name]) => name);
  return names.length ? names.join(" | ") : "OK";
}

export async function load(bytes) {
  const { instance } = await WebAssembly.instantiate(bytes, {});
  const e = instance.exports;
  for (const name of ["memory", "needle_eval", "needle_out", "needle_component_count", "needle_domain", "needle_coupled"]) {
    if (!(name in e)) throw new Error(`needle.wasm does not export ${name}: rebuild it with needle explore`);
  }
  if (e.needle_component_count() !== COMPONENTS.length) {
    throw new Error(`needle.wasm has ${e.needle_component_count()} components, this page ${COMPONENTS.length}: rebuild it with needle explore`);
  }
  const form = ["paper", "coupled", "unfitted"][e.needle_coupled()] ?? "unknown";
  // the compiled-in tissue stacks (names and layer thicknesses), for the insertion player
  const stacks = [];
  for (let s = 0; s < (e.needle_stack_count?.() ?? 0); s++) {
    const name = new TextDecoder().decode(new Uint8Array(e.memory.buffer, e.needle_stack_name(s), e.needle_stack_name_len(s)));
    const thickness_mm = [];
    for (let l = 0; l < e.needle_stack_layer_count(s); l++) thickness_mm.push(e.needle_stack_thickness_mm(s, l));
    stacks.push({ name, thickness_mm });
  }
  // the started path stepped through `poses`: per tick the depth, fy and the punctures
  const steps = (poses) => poses.map((p) => {
    const r = e.needle_insertion_step(p.x_mm, p.z_mm, p.theta_x_deg, p.theta_z_deg, p.depth_mm) >>> 0;
    const w = new Float32Array(Uint32Array.from(new Uint32Array(e.memory.buffer, e.needle_out(), COMPONENTS.length)).buffer);
    return { depth_mm: p.depth_mm, fy_n: w[1], punctures: (r >>> 24) & 0xf, phase: (r >>> 8) & 0xffff };
  });
  return {
    form,
    stacks,
    // a scripted insertion through stack `s` at 1 kHz: returns per tick the depth, fy and
    // the punctures (the firmware's own insertion model). `prony`: null for the stack's own
    // terms, or up to 3 { g, tau_s } tried on every layer (needle_insertion_start_prony)
    insert(s, poses, prony = null) {
      const t = prony ?? [];
      const term = (i) => [t[i]?.g ?? 0, t[i]?.tau_s ?? 0];
      const started = prony === null
        ? e.needle_insertion_start(s, 0.001, 0.005)
        : e.needle_insertion_start_prony(s, 0.001, 0.005, t.length, ...term(0), ...term(1), ...term(2));
      if (started === -3) throw new Error("Prony terms refused: at most 3, each g >= 0 and tau_s > 0 s, sum of g <= 9");
      if (started !== 0) throw new Error(`stack ${s}: cannot start`);
      return steps(poses);
    },
    // the same through a stack given as layers (a tissue file the server loaded, or one
    // drawn within its spread: /stacks.json): { needle_diameter_mm, words: one array of
    // needle_layer_words() numbers per layer (crates/wasm/src/layer_words.rs) }
    insertLayers(stack, poses) {
      if (!("needle_insertion_start_layers" in e)) throw new Error("needle.wasm plays no tissue files: rebuild it with needle explore");
      const n = e.needle_layer_words();
      const words = new Float32Array(e.memory.buffer, e.needle_layers_in(), 8 * n);
      words.fill(0);
      stack.words.forEach((w, l) => words.set(w, l * n));
      const started = e.needle_insertion_start_layers(stack.words.length, stack.needle_diameter_mm, 0.001, 0.005);
      if (started !== 0) throw new Error(`the tissue file's layers are refused (${started})`);
      return steps(poses);
    },
    domain: {
      x_max_mm: e.needle_domain(0),
      z_max_mm: e.needle_domain(1),
      theta_max_deg: e.needle_domain(2),
      depth_max_mm: e.needle_domain(3),
    },
    evaluate(x_mm, z_mm, theta_x_deg, theta_z_deg, depth_mm) {
      const status = e.needle_eval(x_mm, z_mm, theta_x_deg, theta_z_deg, depth_mm) >>> 0;
      // the memory may have grown since the last call: take a fresh view each time
      const bits = Uint32Array.from(new Uint32Array(e.memory.buffer, e.needle_out(), COMPONENTS.length));
      return { status, bits, wrench: new Float32Array(bits.buffer) };
    },
  };
}

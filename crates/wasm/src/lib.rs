//! The f32 evaluator of `needle-haptics` as a WebAssembly module, for `needle explore`.
//!
//! Built with `cargo build --release -p needle-wasm --target wasm32-unknown-unknown`
//! and `NEEDLE_COEFFS` naming the set: the same `no_std` library and the same generated
//! tables as the firmware, so the browser shows what the device will render, bit for bit
//! (`tests/explore_wasm.rs` replays `golden-f32.csv` through the module under Node).
//!
//! The exports use only numbers (no allocator, no bindings generator):
//! - [`needle_eval`] evaluates one pose and returns the status bits; the wrench
//!   components (fx, fy, fz in N; mx, my, mz in N*mm) are left, as f32 bit patterns, in
//!   the buffer of [`needle_component_count`] words at [`needle_out`];
//! - [`needle_domain`] the model's domain, [`needle_coupled`] its form;
//! - the insertion model through the compiled-in tissue stacks: [`needle_stack_count`],
//!   [`needle_insertion_start`] (one path at a time; [`needle_insertion_start_prony`]
//!   with Prony terms tried on every layer) and [`needle_insertion_step`], whose
//!   wrench is left at [`needle_out`] as [`needle_eval`]'s is; the fixed-point insertion
//!   the same way ([`needle_fixed_insertion_start`], [`needle_fixed_insertion_step`]:
//!   Q16.16 poses, the wrench in µN and µN·mm as `i32` bits);
//! - a stack given by the page instead of a compiled-in one (a tissue file the host
//!   loaded, or one drawn within its spread: `needle explore --stack`): its layers as
//!   [`layer_words`] at [`needle_layers_in`], then [`needle_insertion_start_layers`].
#![cfg_attr(target_arch = "wasm32", no_std)]
#![deny(missing_docs)]

use core::sync::atomic::{AtomicU32, Ordering};
use needle_contract::COMPONENT_COUNT;
use needle_haptics::fixed;
use needle_haptics::fixed::insertion::{stacks as fixed_stacks, Insertion as FixedInsertion, InsertionConfig as FixedConfig};
use needle_haptics::insertion::{stacks, Insertion, InsertionConfig, MAX_LAYERS};
use needle_haptics::{model_info, wrench, Pose};

pub mod layer_words;

/// The last evaluation: fx, fy, fz (N), mx, my, mz (N*mm) as f32 bits.
static OUT: [AtomicU32; COMPONENT_COUNT] = [const { AtomicU32::new(0) }; COMPONENT_COUNT];

/// Evaluates the wrench at `x_mm`, `z_mm` (entry point), `theta_x_deg`, `theta_z_deg`
/// (tilt) and `depth_mm`, exactly as the firmware's `needle_haptics::wrench`; stores it
/// at [`needle_out`] and returns the status bits (`Status`: saturation flags 0x1f,
/// `FE_UNSOLVED` 0x20 (the pose lies where the set's FE could not solve; the wrench is
/// still the model's), `NO_MODEL` 0x40, `ERROR` 0x80).
#[cfg_attr(target_arch = "wasm32", no_mangle)]
pub extern "C" fn needle_eval(x_mm: f32, z_mm: f32, theta_x_deg: f32, theta_z_deg: f32, depth_mm: f32) -> u32 {
    let e = wrench(&Pose::new(x_mm, z_mm, theta_x_deg, theta_z_deg, depth_mm));
    for (slot, v) in OUT.iter().zip(e.wrench.to_array()) {
        slot.store(v.to_bits(), Ordering::Relaxed);
    }
    u32::from(e.status.bits())
}

/// Number of wrench components, the words at [`needle_out`] (the contract's
/// `COMPONENT_COUNT`; the page checks its component list against it).
#[cfg_attr(target_arch = "wasm32", no_mangle)]
pub extern "C" fn needle_component_count() -> u32 {
    COMPONENT_COUNT as u32
}

/// Address of the result buffer of [`needle_eval`] in the module's memory.
#[cfg_attr(target_arch = "wasm32", no_mangle)]
pub extern "C" fn needle_out() -> *const AtomicU32 {
    OUT.as_ptr()
}

/// The model's domain: `k` = 0 `X_MAX_MM`, 1 `Z_MAX_MM`, 2 `THETA_MAX_DEG` (both tilts),
/// 3 `DEPTH_MAX_MM`; positions and tilts range over [-max, max], depth over [0, max].
/// Any other `k`: NaN.
#[cfg_attr(target_arch = "wasm32", no_mangle)]
pub extern "C" fn needle_domain(k: u32) -> f32 {
    match k {
        0 => model_info::X_MAX_MM,
        1 => model_info::Z_MAX_MM,
        2 => model_info::THETA_MAX_DEG,
        3 => model_info::DEPTH_MAX_MM,
        _ => f32::NAN,
    }
}

/// 1 when the compiled model is the coupled form (cross terms), 0 for the paper's
/// superposition; 2 when no model is fitted (every evaluation returns `NO_MODEL`).
#[cfg_attr(target_arch = "wasm32", no_mangle)]
pub extern "C" fn needle_coupled() -> u32 {
    if !model_info::FITTED {
        2
    } else {
        u32::from(model_info::COUPLED)
    }
}

/// The page's one needle path (a wasm instance runs on one thread).
struct Path(core::cell::RefCell<Option<Insertion>>);

// SAFETY: wasm32-unknown-unknown without the atomics feature has one thread; on the host
// (tests) nothing shares the static across threads either: the exports are called from
// one thread at a time by the embedder.
unsafe impl Sync for Path {}

static PATH: Path = Path(core::cell::RefCell::new(None));

/// Number of compiled-in tissue stacks (indices for [`needle_insertion_start`]).
#[cfg_attr(target_arch = "wasm32", no_mangle)]
pub extern "C" fn needle_stack_count() -> u32 {
    stacks::ALL.len() as u32
}

/// Address of stack `stack`'s name (UTF-8, [`needle_stack_name_len`] bytes) in the
/// module's memory; null for an unknown stack.
#[cfg_attr(target_arch = "wasm32", no_mangle)]
pub extern "C" fn needle_stack_name(stack: u32) -> *const u8 {
    stacks::ALL.get(stack as usize).map_or(core::ptr::null(), |s| s.name.as_ptr())
}

/// Length of stack `stack`'s name in bytes (0 for an unknown stack).
#[cfg_attr(target_arch = "wasm32", no_mangle)]
pub extern "C" fn needle_stack_name_len(stack: u32) -> u32 {
    stacks::ALL.get(stack as usize).map_or(0, |s| s.name.len() as u32)
}

/// Number of layers of stack `stack` (0 for an unknown stack).
#[cfg_attr(target_arch = "wasm32", no_mangle)]
pub extern "C" fn needle_stack_layer_count(stack: u32) -> u32 {
    stacks::ALL.get(stack as usize).map_or(0, |s| s.layers.len() as u32)
}

/// Thickness of layer `layer` of stack `stack`, mm (NaN for an unknown one).
#[cfg_attr(target_arch = "wasm32", no_mangle)]
pub extern "C" fn needle_stack_thickness_mm(stack: u32, layer: u32) -> f32 {
    stacks::ALL.get(stack as usize).and_then(|s| s.layers.get(layer as usize)).map_or(f32::NAN, |l| l.thickness_mm)
}

/// Starts a needle path through stack `stack` (an index below [`needle_stack_count`]),
/// ticked every `period_s` s, the velocity low-passed with `velocity_time_constant_s` s.
/// Returns 0, or -1 for an unknown stack, -2 for a period or time constant out of range.
#[cfg_attr(target_arch = "wasm32", no_mangle)]
pub extern "C" fn needle_insertion_start(stack: u32, period_s: f32, velocity_time_constant_s: f32) -> i32 {
    let Some(s) = stacks::ALL.get(stack as usize) else { return -1 };
    start_path(s, InsertionConfig { period_s, velocity_time_constant_s, ..InsertionConfig::DEFAULT_1KHZ })
}

/// Starts the page's path through `stack`: 0, or -2 for a configuration out of range.
fn start_path(stack: &needle_haptics::insertion::Stack<'_>, config: InsertionConfig) -> i32 {
    match Insertion::new(stack, config) {
        Ok(i) => {
            *PATH.0.borrow_mut() = Some(i);
            0
        }
        Err(_) => -2,
    }
}

/// Starts a needle path as [`needle_insertion_start`] does, with the Prony terms
/// `(g0, tau0_s)`, `(g1, tau1_s)`, `(g2, tau2_s)` (the first `count`, 0 ..= 3; the
/// library's normalisation: the layer's elastic response is the long-term one) on every
/// layer of stack `stack` in place of its own: the explorer's relaxation view, where a
/// user tries terms on a compiled-in stack. Returns 0, -1 for an unknown stack, -2 for a
/// period or time constant out of range, -3 for terms the tissue files would refuse
/// (`PronyTerms::new`: g >= 0, tau > 0 s, sum of g <= 9).
#[cfg_attr(target_arch = "wasm32", no_mangle)]
#[allow(clippy::too_many_arguments)] // numbers only: the module has no allocator or bindings
pub extern "C" fn needle_insertion_start_prony(
    stack: u32,
    period_s: f32,
    velocity_time_constant_s: f32,
    count: u32,
    g0: f32,
    tau0_s: f32,
    g1: f32,
    tau1_s: f32,
    g2: f32,
    tau2_s: f32,
) -> i32 {
    use needle_haptics::insertion::{Layer, Stack, MAX_LAYERS};
    use needle_haptics::viscoelastic::{PronyTerm, PronyTerms};
    let Some(s) = stacks::ALL.get(stack as usize) else { return -1 };
    let all = [PronyTerm { g: g0, tau_s: tau0_s }, PronyTerm { g: g1, tau_s: tau1_s }, PronyTerm { g: g2, tau_s: tau2_s }];
    let Some(chosen) = all.get(..count as usize) else { return -3 };
    let Ok(terms) = PronyTerms::new(chosen) else { return -3 };
    let Some(first) = s.layers.first() else { return -1 };
    let mut layers: [Layer; MAX_LAYERS] = [*first; MAX_LAYERS];
    for (slot, l) in layers.iter_mut().zip(s.layers) {
        *slot = Layer { prony: terms, ..*l };
    }
    let with = Stack { layers: layers.get(..s.layers.len()).unwrap_or(&[]), ..*s };
    start_path(&with, InsertionConfig { period_s, velocity_time_constant_s, ..InsertionConfig::DEFAULT_1KHZ })
}

/// The page's layers for [`needle_insertion_start_layers`]: [`MAX_LAYERS`] layers of
/// [`layer_words::LAYER_WORDS`] f32 words each, as bits.
static LAYERS_IN: [AtomicU32; MAX_LAYERS * layer_words::LAYER_WORDS] = [const { AtomicU32::new(0) }; MAX_LAYERS * layer_words::LAYER_WORDS];

/// Words per layer at [`needle_layers_in`] ([`layer_words::LAYER_WORDS`]).
#[cfg_attr(target_arch = "wasm32", no_mangle)]
pub extern "C" fn needle_layer_words() -> u32 {
    layer_words::LAYER_WORDS as u32
}

/// Address of the buffer the page writes a stack's layers to (f32 words, layer after
/// layer, [`needle_layer_words`] each, at most `MAX_LAYERS` = 8 layers).
#[cfg_attr(target_arch = "wasm32", no_mangle)]
pub extern "C" fn needle_layers_in() -> *const AtomicU32 {
    LAYERS_IN.as_ptr()
}

/// Starts a needle path through the `count` layers at [`needle_layers_in`] (a stack of
/// a needle of `needle_diameter_mm`), as [`needle_insertion_start`] does for a
/// compiled-in one. Returns 0, -1 for a count of 0 or above `MAX_LAYERS`, -3 for a layer
/// whose words are refused ([`layer_words::from_words`]), -2 for a stack or
/// configuration the insertion refuses (`Insertion::new`: the checks a compiled-in stack
/// passed at build time).
#[cfg_attr(target_arch = "wasm32", no_mangle)]
pub extern "C" fn needle_insertion_start_layers(count: u32, needle_diameter_mm: f32, period_s: f32, velocity_time_constant_s: f32) -> i32 {
    use needle_haptics::insertion::{Layer, Stack};
    let n = count as usize;
    if n == 0 || n > MAX_LAYERS {
        return -1;
    }
    let words: [f32; MAX_LAYERS * layer_words::LAYER_WORDS] =
        core::array::from_fn(|i| LAYERS_IN.get(i).map_or(0.0, |w| f32::from_bits(w.load(Ordering::Relaxed))));
    let mut layers: [Option<Layer>; MAX_LAYERS] = [None; MAX_LAYERS];
    for (slot, w) in layers.iter_mut().zip(words.chunks_exact(layer_words::LAYER_WORDS)).take(n) {
        *slot = layer_words::from_words(w);
    }
    let Some(Some(first)) = layers.first().copied() else { return -3 };
    let mut out: [Layer; MAX_LAYERS] = [first; MAX_LAYERS];
    for (o, l) in out.iter_mut().zip(&layers).take(n) {
        let Some(l) = l else { return -3 };
        *o = *l;
    }
    let stack = Stack { name: "page", needle_diameter_mm, layers: out.get(..n).unwrap_or(&[]) };
    start_path(&stack, InsertionConfig { period_s, velocity_time_constant_s, ..InsertionConfig::DEFAULT_1KHZ })
}

/// One tick of the started path: the wrench at [`needle_out`]; returns
/// `status | phase_code << 8 | punctures << 24 | flags << 28` (phase code: 0 approach,
/// 0x100 | layer deflecting, 0x200 | layer cutting, 0x300 | layer in the track;
/// punctures at most 8, four bits; flags the step's `InsertionFlags`, four bits), or
/// `u32::MAX` when no path was started.
#[cfg_attr(target_arch = "wasm32", no_mangle)]
pub extern "C" fn needle_insertion_step(x_mm: f32, z_mm: f32, theta_x_deg: f32, theta_z_deg: f32, depth_mm: f32) -> u32 {
    let mut path = PATH.0.borrow_mut();
    let Some(ins) = path.as_mut() else { return u32::MAX };
    let e = ins.step(&Pose::new(x_mm, z_mm, theta_x_deg, theta_z_deg, depth_mm));
    for (slot, v) in OUT.iter().zip(e.wrench.to_array()) {
        slot.store(v.to_bits(), Ordering::Relaxed);
    }
    packed(e.status.bits(), e.phase.code(), e.punctures, e.flags.bits())
}

/// A tick's result in one word: `status | phase_code << 8 | punctures << 24 | flags << 28`
/// (the phase code has 10 bits, punctures at most [`MAX_LAYERS`](needle_haptics::insertion::MAX_LAYERS) = 8 and
/// the flags four bits).
fn packed(status: u8, phase: u16, punctures: u8, flags: u8) -> u32 {
    u32::from(status) | u32::from(phase) << 8 | u32::from(punctures & 0x0f) << 24 | u32::from(flags & 0x0f) << 28
}

/// The fixed-point needle path (`needle_haptics::fixed::insertion`).
struct FixedPath(core::cell::RefCell<Option<FixedInsertion<'static>>>);

// SAFETY: as `Path`'s: one thread.
unsafe impl Sync for FixedPath {}

static FIXED_PATH: FixedPath = FixedPath(core::cell::RefCell::new(None));

/// Starts a fixed-point needle path through stack `stack`, ticked every `period_us` µs,
/// the velocity low-passed with `velocity_time_constant_us` µs. Returns 0, or -1 for an
/// unknown stack, -2 for a zero period.
#[cfg_attr(target_arch = "wasm32", no_mangle)]
pub extern "C" fn needle_fixed_insertion_start(stack: u32, period_us: u32, velocity_time_constant_us: u32) -> i32 {
    let Some(s) = fixed_stacks::ALL.get(stack as usize) else { return -1 };
    match FixedInsertion::new(s, FixedConfig { period_us, velocity_time_constant_us, ..FixedConfig::DEFAULT_1KHZ }) {
        Ok(i) => {
            *FIXED_PATH.0.borrow_mut() = Some(i);
            0
        }
        Err(_) => -2,
    }
}

/// One tick of the started fixed-point path, the pose in Q16.16 (mm, degrees × 65536):
/// the wrench (µN, µN·mm, as `i32` bits) at [`needle_out`]; returns what
/// [`needle_insertion_step`] returns, or `u32::MAX` when no path was started.
#[cfg_attr(target_arch = "wasm32", no_mangle)]
pub extern "C" fn needle_fixed_insertion_step(
    x_mm_q16: i32,
    z_mm_q16: i32,
    theta_x_deg_q16: i32,
    theta_z_deg_q16: i32,
    depth_mm_q16: i32,
) -> u32 {
    let mut path = FIXED_PATH.0.borrow_mut();
    let Some(ins) = path.as_mut() else { return u32::MAX };
    let e = ins.step(&fixed::Pose::new(x_mm_q16, z_mm_q16, theta_x_deg_q16, theta_z_deg_q16, depth_mm_q16));
    for (slot, v) in OUT.iter().zip(e.wrench.to_array()) {
        slot.store(v as u32, Ordering::Relaxed);
    }
    packed(e.status.bits(), e.phase.code(), e.punctures, e.flags.bits())
}

/// A wasm module has no one to report a panic to; the library cannot panic (its
/// link-time check), so this is never reached.
#[cfg(target_arch = "wasm32")]
#[panic_handler]
fn panic(_: &core::panic::PanicInfo<'_>) -> ! {
    core::arch::wasm32::unreachable()
}

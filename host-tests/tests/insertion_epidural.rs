//! The shipped `epidural` stack renders the loss of resistance: inserted at a steady
//! speed, the axial force drops where the tip leaves the ligamentum flavum (the
//! puncture into the epidural space) from the ligamentum flavum's cutting force to the
//! epidural space's level, the largest drop of the insertion, and stays there.
use needle_haptics::insertion::{stacks, Insertion, InsertionConfig, Phase};
use needle_haptics::{Pose, Status};

const SPEED_MM_PER_S: f32 = 3.0;

/// (depth mm, axial force N, punctures, phase) per tick of a vertical insertion at
/// [`SPEED_MM_PER_S`] from 1 mm above the surface to 1 mm short of the stack's bottom.
fn insert() -> Vec<(f32, f32, u8, Phase)> {
    let stack = &stacks::EPIDURAL;
    let total: f32 = stack.layers.iter().map(|l| l.thickness_mm).sum();
    let mut ins = Insertion::new(stack, InsertionConfig::DEFAULT_1KHZ).expect("shipped stack");
    let step = SPEED_MM_PER_S * InsertionConfig::DEFAULT_1KHZ.period_s;
    let ticks = ((total - 1.0 + 1.0) / step) as u32;
    (0..=ticks)
        .map(|k| {
            let depth = -1.0 + step * k as f32;
            let e = ins.step(&Pose { depth_mm: depth, ..Pose::default() });
            // every boundary deflects inside the FE surrogate's domain and its depth
            // extension (the skin's 14.6 mm is 8.8 mm on the FE needle: lambda = 1.651)
            assert_eq!(e.status, Status::OK, "status {:?} at {depth} mm", e.status);
            (depth, e.wrench.fy_n, e.punctures, e.phase)
        })
        .collect()
}

/// The index of the layer `name` in the shipped file (the library keeps no names).
fn index(name: &str) -> usize {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../coeffs/default/tissue/epidural.toml");
    let file = needle_codegen::tissue::parse_stack(&path).unwrap_or_else(|e| panic!("{e}"));
    file.layers.iter().position(|l| l.name == name).unwrap_or_else(|| panic!("no layer {name:?}"))
}

#[test]
fn the_force_drops_at_the_ligamentum_flavum_puncture_to_the_epidural_space_level() {
    let layers = stacks::EPIDURAL.layers;
    let (lf, es) = (index("ligamentum flavum"), index("epidural space"));
    assert_eq!(es, layers.len() - 1, "the epidural space is the last layer");
    let ticks = insert();
    let in_es = |p: Phase| matches!(p, Phase::Deflecting(l) | Phase::Cutting(l) | Phase::InTrack(l) if usize::from(l) == es);
    // the tip reaches the epidural space's top (the ligamentum flavum's cutting force carried onto it) and
    // punctures into it within a tick (its boundary has no force of its own)
    let into_es = ticks.iter().position(|t| in_es(t.3)).expect("the insertion reaches the epidural space");
    let punctured = ticks.iter().position(|t| t.2 > 0 && in_es(t.3)).expect("the insertion punctures into the epidural space");
    assert!(punctured - into_es <= 1, "punctured {} ticks after reaching the epidural space", punctured - into_es);
    let (before, at) = (ticks[punctured - 1], ticks[punctured]);
    // before: cutting the ligamentum flavum at full speed (or, the tip exactly on the
    // epidural space's top, deflecting it with that cutting force carried), plus the
    // friction of every layer passed
    let friction = |upto: usize| -> f32 { layers.iter().take(upto).map(|l| l.thickness_mm * l.friction.coulomb_n_per_mm).sum() };
    let (lf_phase, es_top) = (Phase::Cutting(u8::try_from(lf).expect("index")), Phase::Deflecting(u8::try_from(es).expect("index")));
    assert!(before.3 == lf_phase || (before.3 == es_top && punctured == into_es + 1), "{before:?}");
    let lf_level = layers[lf].cutting_force_n + friction(lf + 1);
    assert!((before.1 - lf_level).abs() <= 1e-4 * lf_level, "before the drop {} N, the ligamentum flavum's level {lf_level} N", before.1);
    // from then on: the epidural space's level (its cutting force, ramped in from the
    // stick band at this speed, and the friction of every layer above it)
    let es_level = layers[es].cutting_force_n + friction(es);
    assert!((at.1 - es_level).abs() <= 1e-3, "after the drop {} N, the epidural space's level {es_level} N", at.1);
    assert!(before.1 - at.1 >= 0.9 * lf_level, "a loss of resistance: {} N -> {} N", before.1, at.1);
    // where the published model drops (its ES piece's top, the layers above it), within a tick
    let top: f32 = layers.iter().take(es).map(|l| l.thickness_mm).sum();
    assert!((at.0 - top).abs() <= SPEED_MM_PER_S * 0.001 + 1e-4, "puncture at {} mm, the epidural space's top {top} mm", at.0);
    // the largest drop of the whole insertion, and the force stays at the level after it
    let largest = ticks.windows(2).map(|w| w[0].1 - w[1].1).fold(f32::NEG_INFINITY, f32::max);
    assert_eq!(largest, before.1 - at.1, "the loss of resistance is the largest drop");
    for t in &ticks[punctured..] {
        assert!(in_es(t.3), "left the epidural space at {} mm", t.0);
        assert!((t.1 - es_level).abs() <= 1e-3, "in the epidural space at {} mm: {} N", t.0, t.1);
    }
    println!("loss of resistance at {:.3} mm: {:.4} N -> {:.4} N", at.0, before.1, at.1);
}

#[test]
fn every_boundary_of_the_epidural_stack_is_punctured_in_order() {
    let ticks = insert();
    let mut order = Vec::new();
    for t in ticks.iter().filter(|t| t.2 > 0) {
        order.push((t.0, t.2, t.3));
    }
    let total: u32 = order.iter().map(|o| u32::from(o.1)).sum();
    assert_eq!(total as usize, stacks::EPIDURAL.layers.len(), "one puncture per boundary: {order:?}");
    println!("punctures (depth mm, count, phase after): {order:?}");
}

/// No false loss of resistance: inserted at a steady speed, the force only falls in a
/// tick with a puncture (where the tip meets a boundary, the cutting force of the layer
/// above is carried onto it). Between punctures the deflection rises, cutting is steady
/// and the friction grows with the shaft inside: 1e-4 N of the 12 N peak covers f32
/// round-off of the sums (a few ulp, 1e-6 N), far below the 0.7 N to 7.5 N of the
/// dips this rules out.
#[test]
fn a_steady_insertion_loses_force_only_at_a_puncture() {
    let ticks = insert();
    let falls: Vec<_> =
        ticks.windows(2).filter(|w| w[1].2 == 0 && w[1].1 < w[0].1 - 1e-4).map(|w| (w[1].0, w[0].1, w[1].1, w[1].3)).collect();
    assert!(falls.is_empty(), "the force falls without a puncture (depth mm, N before, N after, phase): {falls:?}");
}

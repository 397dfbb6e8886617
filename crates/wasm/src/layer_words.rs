//! A tissue layer as [`LAYER_WORDS`] f32 numbers: how a stack loaded or drawn on the
//! host (`needle explore --stack FILE`: a tissue file, and tissues drawn within its
//! spread) reaches the module, which has no allocator and takes numbers only. The host
//! writes [`to_words`] of each layer ([`needle_haptics::insertion::Layer`], as the
//! host's own insertion takes it), the module reads them back with [`from_words`]: the
//! same layer, bit for bit. The order of the words is defined here only.
use needle_haptics::insertion::{FamilyMember, Karnopp, Layer, Presliding, Softening};
use needle_haptics::viscoelastic::{PronyTerm, PronyTerms, MAX_TERMS};

/// Words of one Prony set: the count, then `g`, `tau_s` of each term (unused terms 0).
const PRONY_WORDS: usize = 1 + 2 * MAX_TERMS;

/// Words per layer: thickness mm, stiffness scale, puncture N, cutting N, the Karnopp
/// friction (static, Coulomb N/mm, viscous N·s/mm², stick band mm/s), track stiffness
/// N/mm², the Prony set, the family weight, the softening (fraction, onset ratio), the
/// presliding (distance mm, relaxation slip mm, the shaft's Prony set, the tissue's tent
/// N/mm).
pub const LAYER_WORDS: usize = 9 + PRONY_WORDS + 3 + 2 + PRONY_WORDS + 1;

fn prony_words(p: &PronyTerms) -> [f32; PRONY_WORDS] {
    let (terms, count) = p.as_array();
    let mut out = [0.0; PRONY_WORDS];
    let values = terms.iter().take(usize::from(count)).flat_map(|t| [t.g, t.tau_s]);
    for (slot, v) in out.iter_mut().zip(core::iter::once(f32::from(count)).chain(values)) {
        *slot = v;
    }
    out
}

/// The Prony set of `w` (its words), `None` for a count above [`MAX_TERMS`] or terms the
/// library refuses.
fn prony_from(w: &[f32]) -> Option<PronyTerms> {
    let word = *w.first()?;
    let count = (0..=MAX_TERMS).find(|&k| k as f32 == word)?;
    let mut terms = [PronyTerm { g: 0.0, tau_s: 0.0 }; MAX_TERMS];
    for (k, t) in terms.iter_mut().enumerate().take(count) {
        *t = PronyTerm { g: *w.get(1 + 2 * k)?, tau_s: *w.get(2 + 2 * k)? };
    }
    PronyTerms::new(terms.get(..count)?).ok()
}

/// The words of `l` ([`LAYER_WORDS`], module docs).
#[must_use]
pub fn to_words(l: &Layer) -> [f32; LAYER_WORDS] {
    let f = &l.friction;
    let head = [
        l.thickness_mm,
        l.stiffness_scale,
        l.puncture_force_n,
        l.cutting_force_n,
        f.static_n_per_mm,
        f.coulomb_n_per_mm,
        f.viscous_n_s_per_mm2,
        f.stick_band_mm_per_s,
        l.track_stiffness_n_per_mm2,
    ];
    let mid = [l.family.weight(), l.softening.fraction, l.softening.onset_ratio];
    let slide = [l.presliding.distance_mm, l.presliding.relaxation_slip_mm];
    let mut out = [0.0; LAYER_WORDS];
    let tent = [l.presliding.tent_n_per_mm];
    let parts: [&[f32]; 6] = [&head, &prony_words(&l.prony), &mid, &slide, &prony_words(&l.presliding.shaft_prony), &tent];
    for (slot, v) in out.iter_mut().zip(parts.into_iter().flatten()) {
        *slot = *v;
    }
    out
}

/// The layer of `w` (at least [`LAYER_WORDS`] words, [`to_words`]' order); `None` when
/// there are too few, a Prony set is refused by the library, or the family weight is not
/// within 0 to 1 (the insertion checks the rest when it starts).
#[must_use]
pub fn from_words(w: &[f32]) -> Option<Layer> {
    let head = w.get(..9)?;
    let [thickness_mm, stiffness_scale, puncture_force_n, cutting_force_n, s, c, v, band, track] = *head else { return None };
    let prony = prony_from(w.get(9..9 + PRONY_WORDS)?)?;
    let at = 9 + PRONY_WORDS;
    let [weight, fraction, onset_ratio, distance_mm, relaxation_slip_mm] = *w.get(at..at + 5)? else { return None };
    let shaft_prony = prony_from(w.get(at + 5..at + 5 + PRONY_WORDS)?)?;
    let tent_n_per_mm = *w.get(at + 5 + PRONY_WORDS)?;
    Some(Layer {
        thickness_mm,
        stiffness_scale,
        puncture_force_n,
        cutting_force_n,
        friction: Karnopp { static_n_per_mm: s, coulomb_n_per_mm: c, viscous_n_s_per_mm2: v, stick_band_mm_per_s: band },
        track_stiffness_n_per_mm2: track,
        prony,
        family: FamilyMember::new(weight)?,
        softening: Softening { fraction, onset_ratio },
        presliding: Presliding { distance_mm, relaxation_slip_mm, shaft_prony, tent_n_per_mm },
    })
}

//! One rule for the shaft terms' slip distances: the hold's fit loads each arm within
//! the stick band's edge times its time constant (`ShaftGuess::slip_mm`, at most the
//! presliding distance), the stack keeps the shortest term's (`relaxation_slip_mm`) and
//! the library loads each term within it times `tau_i / tau_min`
//! (`Presliding::term_slip_mm`). They must give every term the same distance, on the
//! rig's 100 Hz trials and on a rig that samples at 1 kHz (the grid's shortest time
//! constant is three sampling periods: 3 ms, so the shortest arm is loaded within
//! 0.003 mm at a stick band's edge of 1 mm/s; before the relaxation slip distance had a
//! range of its own, the fit clamped it to 0.01 mm and the library then loaded a 50 ms
//! term within 0.167 mm where the fit had assumed 0.050 mm).
use needle_calibrate::whole::hold::ShaftGuess;
use needle_haptics::insertion::Presliding;
use needle_haptics::viscoelastic::{PronyTerm, PronyTerms};

/// The stick band's edge the rig's calibrations write, mm/s (`stick_band_mm_per_s`).
const SLIP_SPEED_MM_PER_S: f64 = 0.9934;
const PRESLIDING_MM: f64 = 1.5;

/// The stack's presliding for a fit with these time constants, as the calibration writes
/// it: the relaxation slip distance is the shortest term's.
fn written(guess: &ShaftGuess, taus_s: &[f64]) -> Presliding {
    let terms: Vec<PronyTerm> = taus_s.iter().map(|&tau| PronyTerm { g: 0.5, tau_s: tau as f32 }).collect();
    let slip = taus_s.iter().map(|&tau| guess.slip_mm(tau)).fold(f64::INFINITY, f64::min);
    Presliding {
        distance_mm: PRESLIDING_MM as f32,
        relaxation_slip_mm: slip as f32,
        shaft_prony: PronyTerms::new(&terms).expect("valid terms"),
        tent_n_per_mm: 0.0,
    }
}

#[test]
fn the_fit_and_the_library_load_each_shaft_term_within_the_same_distance() {
    let guess = ShaftGuess { presliding_mm: PRESLIDING_MM, cutting_n: 0.0, slip_speed_mm_per_s: SLIP_SPEED_MM_PER_S };
    for (rig, taus_s) in [("100 Hz", [0.03, 0.66, 5.5]), ("1 kHz", [0.003, 0.05, 2.0])] {
        let p = written(&guess, &taus_s);
        assert!(p.is_valid(), "{rig}: the library refuses the written presliding {p:?}");
        for tau in taus_s {
            let (fit, library) = (guess.slip_mm(tau), f64::from(p.term_slip_mm(tau as f32)));
            println!("{rig}: term {tau} s: the fit loads it within {fit:.5} mm, the library within {library:.5} mm");
            // f32 storage and arithmetic: a few units in the last place
            assert!(
                (library - fit).abs() <= 1e-6 * fit.max(1.0),
                "{rig}: term {tau} s: the fit assumed {fit} mm, the library loads it within {library} mm"
            );
        }
    }
}

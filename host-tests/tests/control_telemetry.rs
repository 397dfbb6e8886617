//! Telemetry: the SPSC queue keeps order, holds `N - 1` samples, never blocks the
//! producer, and counts every sample dropped while full; samples pushed from a real
//! control loop carry tick, pose, wrench and flags.
mod common;

use common::{golden_in_domain, Script};
use needle_haptics::control::{ChannelMap, LoopConfig, LoopCore, LoopFlags, OverLimit, PoseFault, Sample};
use needle_haptics::telemetry::Telemetry;

fn sample(tick: u32) -> Sample {
    Sample { tick, ..Sample::default() }
}

#[test]
fn full_queue_drops_new_samples_and_counts_them() {
    let mut t: Telemetry<8> = Telemetry::new();
    assert_eq!(t.capacity(), 7);
    let (mut tx, mut rx) = t.split();
    for tick in 1..=7 {
        assert!(tx.push(sample(tick)), "sample {tick} fits");
    }
    assert_eq!(rx.len(), 7);
    assert_eq!(rx.dropped(), 0);
    for tick in 8..=20 {
        assert!(!tx.push(sample(tick)), "queue full at {tick}");
    }
    assert_eq!(rx.dropped(), 13);
    assert_eq!(tx.dropped(), 13);
    // The queued samples are the oldest ones, in order.
    let got: Vec<u32> = std::iter::from_fn(|| rx.pop()).map(|s| s.tick).collect();
    assert_eq!(got, (1..=7).collect::<Vec<_>>());
    assert!(rx.is_empty());
    // Room again; the count is never reset.
    assert!(tx.push(sample(21)));
    assert_eq!(rx.pop().map(|s| s.tick), Some(21));
    assert_eq!(rx.dropped(), 13);
}

#[test]
fn producer_and_consumer_on_two_threads_lose_nothing_but_the_counted() {
    let mut t: Telemetry<16> = Telemetry::new();
    let (mut tx, mut rx) = t.split();
    const N: u32 = 20_000;
    std::thread::scope(|s| {
        s.spawn(move || {
            for tick in 1..=N {
                tx.push(sample(tick));
            }
        });
        let mut received = 0u32;
        let mut last = 0u32;
        loop {
            if let Some(x) = rx.pop() {
                assert!(x.tick > last, "order: {} after {last}", x.tick);
                last = x.tick;
                received += 1;
                if last == N {
                    break;
                }
            } else if received + rx.dropped() == N && rx.is_empty() {
                break;
            }
        }
        // Drain what is left after the producer stopped.
        while rx.pop().is_some() {
            received += 1;
        }
        assert_eq!(received + rx.dropped(), N, "received {received}, dropped {}", rx.dropped());
    });
}

#[test]
fn loop_samples_go_through_the_queue() {
    let rows = golden_in_domain(5);
    let config = LoopConfig {
        channels: [ChannelMap { gains_per_n: [0.0, 10.0, 0.0], direction_inverted: false }],
        force_limit_n: 5.0,
        force_limit_max_n: 5.0,
        over_limit: OverLimit::Saturate,
        // below the 1 mN every row of golden_in_domain pushes with: the stale tick after
        // them still ramps (RAMPING), whatever the fitted model's magnitudes are
        ramp_step_n: 0.001,
    };
    let mut core = LoopCore::new(config).expect("valid");
    let mut script = Script::new(rows.iter().map(|r| Ok(r.pose)));
    script.0.push_back(Err(PoseFault::Stale));
    let mut t: Telemetry<4> = Telemetry::new();
    let (mut tx, mut rx) = t.split();
    for _ in 0..6 {
        let s = core.step(needle_haptics::control::PoseSource::read_pose(&mut script));
        tx.push(s);
    }
    assert_eq!(rx.dropped(), 3);
    for r in rows.iter().take(3) {
        let s = rx.pop().expect("queued");
        assert_eq!(s.pose, r.pose);
        assert_eq!(s.wrench.to_array().map(f32::to_bits), r.wrench.to_array().map(f32::to_bits));
        assert_eq!(s.flags, LoopFlags::OK);
    }
    assert_eq!(core.last().flags, LoopFlags::POSE_STALE | LoopFlags::RAMPING);
}

//! Telemetry: tick [`Sample`]s from the control loop (high priority) to a lower-priority
//! consumer (a logger, the host link) through a `heapless` SPSC queue. The loop never
//! blocks: when the queue is full the new sample is dropped and counted.
//!
//! ```
//! use needle_haptics::control::Sample;
//! use needle_haptics::telemetry::Telemetry;
//!
//! let mut t: Telemetry<4> = Telemetry::new(); // holds 3 samples
//! let (mut tx, mut rx) = t.split();
//! for tick in 1..=5 {
//!     tx.push(Sample { tick, ..Sample::default() });
//! }
//! assert_eq!(rx.dropped(), 2);
//! assert_eq!(rx.pop().map(|s| s.tick), Some(1));
//! ```
use crate::control::Sample;
use core::sync::atomic::{AtomicU32, Ordering};
use heapless::spsc::{Consumer, Producer, Queue};

/// The queue and its overflow counter. `N` is heapless's storage size: the queue holds
/// `N - 1` samples (`N` a power of two is fastest).
///
/// Put it in a `static` (or an RTIC resource) and [`split`](Self::split) it once.
pub struct Telemetry<const N: usize> {
    queue: Queue<Sample, N>,
    dropped: AtomicU32,
}

impl<const N: usize> Telemetry<N> {
    /// An empty queue, no sample dropped (`const`, for statics).
    #[must_use]
    pub const fn new() -> Self {
        Self { queue: Queue::new(), dropped: AtomicU32::new(0) }
    }

    /// The number of samples the queue can hold (`N - 1`).
    #[must_use]
    pub const fn capacity(&self) -> usize {
        N - 1
    }

    /// The producer (for the loop) and the consumer (for the lower-priority task).
    pub fn split(&mut self) -> (SampleProducer<'_, N>, SampleConsumer<'_, N>) {
        let (tx, rx) = self.queue.split();
        (SampleProducer { tx, dropped: &self.dropped }, SampleConsumer { rx, dropped: &self.dropped })
    }
}

impl<const N: usize> Default for Telemetry<N> {
    fn default() -> Self {
        Self::new()
    }
}

/// The control loop's end of the queue.
pub struct SampleProducer<'a, const N: usize> {
    tx: Producer<'a, Sample, N>,
    dropped: &'a AtomicU32,
}

impl<const N: usize> SampleProducer<'_, N> {
    /// Queues `sample`; when the queue is full, drops it and adds one to the overflow
    /// count (saturating at `u32::MAX`). Returns whether it was queued. Never blocks, never
    /// panics; a few loads and stores (no read-modify-write atomics, so it works on
    /// Cortex-M0: the producer is the counter's only writer).
    pub fn push(&mut self, sample: Sample) -> bool {
        if self.tx.enqueue(sample).is_ok() {
            return true;
        }
        let n = self.dropped.load(Ordering::Relaxed);
        self.dropped.store(n.saturating_add(1), Ordering::Relaxed);
        false
    }

    /// Samples dropped so far.
    #[must_use]
    pub fn dropped(&self) -> u32 {
        self.dropped.load(Ordering::Relaxed)
    }
}

/// The consumer's end of the queue.
pub struct SampleConsumer<'a, const N: usize> {
    rx: Consumer<'a, Sample, N>,
    dropped: &'a AtomicU32,
}

impl<const N: usize> SampleConsumer<'_, N> {
    /// The oldest queued sample, if any.
    pub fn pop(&mut self) -> Option<Sample> {
        self.rx.dequeue()
    }

    /// Samples waiting.
    #[must_use]
    pub fn len(&self) -> usize {
        self.rx.len()
    }

    /// `true` when no sample waits.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.rx.len() == 0
    }

    /// Samples the producer dropped because the queue was full (never reset).
    #[must_use]
    pub fn dropped(&self) -> u32 {
        self.dropped.load(Ordering::Relaxed)
    }
}

//! Row-parallel evaluation: the pose rows split into one contiguous chunk per core, each
//! written by its own thread straight into its part of the output arrays (no copies).
use crate::poses::pose_at;
use needle_haptics::{Pose, Status};
use numpy::ndarray::{s, ArrayView2};

/// Below this many rows per thread a second thread costs more than it saves.
const MIN_ROWS_PER_THREAD: usize = 32_768;

/// For every row: `eval(pose, wrench_row, extra_row)` returns the status; `wrench` is
/// `n * 6` values, `extra` `n * extra_width` (or empty with width 0), `status` `n`.
/// Returns the first row whose status has the ERROR bit.
pub fn for_each_row<F>(
    view: &ArrayView2<'_, f32>,
    wrench: &mut [f32],
    extra: &mut [f32],
    extra_width: usize,
    status: &mut [u8],
    eval: F,
) -> Option<usize>
where
    F: Fn(&Pose, &mut [f32], &mut [f32]) -> u8 + Sync,
{
    let n = view.nrows();
    let cores = std::thread::available_parallelism().map_or(1, usize::from);
    let threads = cores.min(n / MIN_ROWS_PER_THREAD).max(1);
    let chunk = n.div_ceil(threads).max(1);
    let mut extra_chunks: Vec<&mut [f32]> = if extra_width == 0 {
        (0..threads).map(|_| <&mut [f32]>::default()).collect()
    } else {
        extra.chunks_mut(chunk * extra_width).collect()
    };
    extra_chunks.resize_with(threads, Default::default);
    let run = |first: usize, w: &mut [f32], x: &mut [f32], st: &mut [u8]| -> Option<usize> {
        let rows = view.slice(s![first..first + st.len(), ..]);
        let mut error = None;
        for (i, (s, w)) in st.iter_mut().zip(w.chunks_mut(6)).enumerate() {
            let x = if extra_width == 0 { &mut [][..] } else { x.get_mut(i * extra_width..(i + 1) * extra_width).unwrap_or(&mut [][..]) };
            *s = eval(&pose_at(&rows, i), w, x);
            if error.is_none() && *s & Status::ERROR.bits() != 0 {
                error = Some(first + i);
            }
        }
        error
    };
    if threads == 1 {
        return run(0, wrench, extra_chunks.first_mut().map_or(&mut [][..], |x| &mut **x), status);
    }
    std::thread::scope(|scope| {
        let handles: Vec<_> = wrench
            .chunks_mut(chunk * 6)
            .zip(status.chunks_mut(chunk))
            .zip(extra_chunks)
            .enumerate()
            .map(|(t, ((w, st), x))| {
                let run = &run;
                scope.spawn(move || run(t * chunk, w, x, st))
            })
            .collect();
        // A worker's panic (a bug) goes on in this thread: PyO3 raises it as PanicException.
        handles.into_iter().filter_map(|h| h.join().unwrap_or_else(|p| std::panic::resume_unwind(p))).min()
    })
}

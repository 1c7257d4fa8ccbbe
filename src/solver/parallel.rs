//! Both cores: a cloth's kernels split into fixed pieces run on Bevy's compute task pool
//! (the engine's own threads; the pool is made on first use outside an app). Every
//! element is computed the same way whichever thread takes its piece, so results do not
//! depend on the number of threads.

use std::cell::Cell;
use std::sync::atomic::{AtomicBool, AtomicU8, Ordering};
use std::sync::{Mutex, OnceLock, PoisonError};

use bevy::tasks::{ComputeTaskPool, TaskPool, TaskPoolBuilder};

/// Elements per piece of work: large enough that a task's bookkeeping is a small share
/// of it, small enough that two threads share the work evenly (measured on the 65,536
/// curtain, 4 limiter sweeps on two cores: 60 ns per particle-substep at 2,048 against
/// 70 at 1,024 and 80–89 at 16,384; `lab/examples/prof.rs`).
pub(super) const CHUNK: usize = 2048;

/// Below this many elements a kernel runs on the calling thread (no task bookkeeping,
/// no allocation). A fork-join on the pool costs about 10 µs here when its thread has
/// gone to sleep between kernels (`lab/examples/scope_cost.rs`), and a substep takes
/// about 20 of them: at 8,192 particles two threads were slower than one (180 against
/// 115 ns per particle-substep in `cloth bench`). One threshold for every kernel: the
/// per-phase times of `lab/examples/prof.rs` at 16,384 showed two threads losing on the
/// light ones (integration: 3–8 against 3 ns), but a whole step was slower with those
/// kept on one thread below 65,536 (16,384: 5.6–6.0 against 5.0 ms per step; 32,768:
/// 8.8–9.6 against 7.9–8.0, `cloth bench --models 1`).
pub(super) const PARALLEL_FROM: usize = 8 * CHUNK;

/// XPBD's kernels on a grid (its colours, the velocity store, the tethers) go to the pool
/// from this many particles: a substep is about 20 of them, each a fork-join, and below
/// it they cost more than the second core bought (`cloth peers --sides 128,256 --solvers
/// ours` with and without `--one-thread`, 20 substeps: at 16,384 particles 17–19 ms a
/// frame on the pool against 13–15 on one thread; at 65,536, 39.5 against 43–50).
pub(super) const XPBD_PARALLEL_FROM: usize = 4 * PARALLEL_FROM;

/// Whether a cloth's kernels may use the compute pool (the default).
static PARALLEL: AtomicBool = AtomicBool::new(true);

thread_local! {
    /// Kernels and shares started from this thread stay on it ([`on_one_thread`]).
    static ONE_THREAD_HERE: Cell<bool> = const { Cell::new(false) };
}

/// Whether kernels and shares started from this thread may use the pool.
fn parallel_here() -> bool {
    PARALLEL.load(Ordering::Relaxed) && !ONE_THREAD_HERE.with(Cell::get)
}

/// Runs `work` with every cloth kernel and every share of cloths it starts kept on the
/// calling thread, whatever other threads do: a thread count for one run, where
/// [`set_parallel`] sets it for the process. Work started from other threads (an app's
/// systems on Bevy's executor) is not affected. The results are the same bits as on the
/// pool; this is for comparing the two side by side.
pub fn on_one_thread<R>(work: impl FnOnce() -> R) -> R {
    /// Puts the thread's setting back, on a panic too.
    struct Restore(bool);
    impl Drop for Restore {
        fn drop(&mut self) {
            ONE_THREAD_HERE.with(|c| c.set(self.0));
        }
    }
    let _restore = Restore(ONE_THREAD_HERE.with(|c| c.replace(true)));
    work()
}

/// Lets a cloth's kernels use Bevy's compute task pool (`true`, the default) or keeps
/// every kernel on the calling thread (`false`), for the whole process. Results are the
/// same bits either way; this is for measuring what the second core buys (`cloth bench`)
/// and for checking that it changes nothing ([`on_one_thread`] for one run only).
pub fn set_parallel(on: bool) {
    PARALLEL.store(on, Ordering::Relaxed);
}

/// The threads a large cloth's kernels use: the compute pool's threads and the calling
/// thread (which works on a scope's tasks while it waits), at most one per core; 1 with
/// [`set_parallel`]`(false)` or inside [`on_one_thread`].
pub fn threads() -> usize {
    if parallel_here() {
        (pool().thread_num() + 1).min(cores())
    } else {
        1
    }
}

/// The cores this process may run on, asked once: `available_parallelism` reads the
/// process's affinity and its control group's quota from the kernel at every call, 27–34
/// µs a call here (21 system calls), and [`share_items`] asks at every phase of a frame.
fn cores() -> usize {
    static CORES: OnceLock<usize> = OnceLock::new();
    *CORES.get_or_init(|| std::thread::available_parallelism().map_or(1, usize::from))
}

/// Bevy's compute task pool; made on first use outside an app with one thread fewer
/// than the cores, as the calling thread works on a scope's tasks too (an app's pool
/// leaves room for its other pools the same way).
pub fn pool() -> &'static TaskPool {
    ComputeTaskPool::get_or_init(|| {
        TaskPoolBuilder::new()
            .num_threads(cores().saturating_sub(1).max(1))
            .thread_name("bevy_cloth compute".to_string())
            .build()
    })
}

/// Runs `work` on every piece, spread over the compute pool when there are
/// `len ≥ PARALLEL_FROM` elements and more than one thread, else in order on this
/// thread. A piece is the same work whichever thread takes it.
pub(super) fn for_each<T: Send>(
    len: usize,
    pieces: impl Iterator<Item = T>,
    work: impl Fn(T) + Sync,
) {
    for_each_from(PARALLEL_FROM, len, pieces, work);
}

/// Whether a kernel of `len` elements with threshold `from` runs in order on the calling
/// thread (as [`for_each_from`] decides), where a kernel may take a serial shortcut.
pub(super) fn on_this_thread(from: usize, len: usize) -> bool {
    len < from || !parallel_here()
}

/// [`for_each`] for a kernel whose own measurements put its threshold at `from` elements.
pub(super) fn for_each_from<T: Send>(
    from: usize,
    len: usize,
    pieces: impl Iterator<Item = T>,
    work: impl Fn(T) + Sync,
) {
    if on_this_thread(from, len) {
        pieces.for_each(work);
        return;
    }
    let work = &work;
    pool().scope(|scope| {
        for piece in pieces {
            scope.spawn(async move { work(piece) });
        }
    });
}

/// Sets every element of `out` by `f(index, element)`, in pieces as `for_each` does:
/// the per-particle kernels that read other arrays by index (normals, the patch pull)
/// and the plugin's mesh write-back.
pub fn for_each_indexed<T: Send>(out: &mut [T], f: impl Fn(usize, &mut T) + Sync) {
    let len = out.len();
    for_each(len, out.chunks_mut(CHUNK).enumerate(), |(piece, out)| {
        for (k, o) in out.iter_mut().enumerate() {
            f(piece * CHUNK + k, o);
        }
    });
}

/// As [`for_each`], for work that reports flags: every piece's, or-ed.
pub(super) fn or_bits<T: Send>(
    len: usize,
    pieces: impl Iterator<Item = T>,
    work: impl Fn(T) -> u8 + Sync,
) -> u8 {
    let found = AtomicU8::new(0);
    for_each(len, pieces, |piece| {
        let bits = work(piece);
        if bits != 0 {
            found.fetch_or(bits, Ordering::Relaxed);
        }
    });
    found.into_inner()
}

/// Shares `items` (each with its estimated work) out among the threads and runs `run`
/// on each: the longest first, each thread taking the next item as soon as it is done
/// with its last (list scheduling, Graham 1969: within 4/3 of the best split when the
/// longest go first). An item's share goes by what it really costs, not by the estimate:
/// split into fixed lots by particles, a crowd's plans put every cape on one thread and
/// every skirt on the other, and the cloths a wind zone reached (whose plans cost more)
/// wherever they fell. One task a thread on the compute pool; the calling thread takes
/// one while it waits on the scope (run inline instead, before the scope ticks, it
/// measured 1.48× against 1.79× for 20 cloths on two cores). With one thread, or one
/// item, all run here in the order given, with nothing allocated.
pub fn share_items<T: Send>(items: impl Iterator<Item = (u64, T)>, run: impl Fn(T) + Sync) {
    let threads = threads();
    let mut items = items.peekable();
    if threads <= 1 {
        items.for_each(|(_, item)| run(item));
        return;
    }
    let Some(first) = items.next() else {
        return;
    };
    if items.peek().is_none() {
        return run(first.1);
    }
    let mut items: Vec<(u64, T)> = std::iter::once(first).chain(items).collect();
    items.sort_by_key(|(w, _)| std::cmp::Reverse(*w));
    let tasks = threads.min(items.len());
    let queue = Mutex::new(items.into_iter().map(|(_, item)| item));
    let (run, queue) = (&run, &queue);
    pool().scope(|scope| {
        for _ in 0..tasks {
            scope.spawn(async move {
                while let Some(item) = take_next(queue) {
                    run(item);
                }
            });
        }
    });
}

/// The next item of `queue`, the lock held only while it is taken (never while an
/// item runs, so no item's panic can poison it; taken over anyway if one did).
fn take_next<T>(queue: &Mutex<impl Iterator<Item = T>>) -> Option<T> {
    queue.lock().unwrap_or_else(PoisonError::into_inner).next()
}

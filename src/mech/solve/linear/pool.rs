//! The numeric factorizations on several threads (issue 42 item 1): the multifrontal LDLᵀ's
//! sibling subtrees and its large fronts' dense kernels (`multifrontal.rs`) run
//! on a rayon pool made for one factorization by
//! `ThreadPoolBuilder::build_scoped`, whose threads are joined before it returns; on Linux the
//! caller then waits until the kernel no longer lists them (`/proc/self/task`), as after the
//! assembly's threads. So no thread outlives a factorization, let alone an FMI call, and
//! rayon's global pool is never started (every faer call here names its `Par`).

use std::sync::Mutex;

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::ldlt::factor::{LdltError, LdltRegularization};
use faer::sparse::SparseColMatRef;
use faer::sparse::linalg::cholesky::LdltRef;
use faer::{Conj, MatMut, Par, Side};

use crate::mech::solve::assembly::{idle_cores, worker};
use crate::mech::solve::linear::multifrontal::{self, Analysed};

/// Factors of at least this many values (128 MiB, the sheet from about 100 k DOF) are
/// factorized on the idle cores when the thread count is automatic; below, one thread (on
/// 20 k DOF a second thread lost 1.1–1.7× on the shared machine).
pub const PARALLEL_MIN_FACTOR: usize = 1 << 24;

/// The parallelism of a factorization on `threads` threads.
pub(super) fn par(threads: usize) -> Par {
    if threads > 1 {
        Par::rayon(threads)
    } else {
        Par::Seq
    }
}

/// The thread count `requested` resolves to for a factor of `factor_len` values: itself when
/// positive, else the idle cores ([`idle_cores`]) from [`PARALLEL_MIN_FACTOR`] values, else 1.
pub(super) fn resolve(requested: usize, factor_len: usize) -> usize {
    match requested {
        0 if factor_len < PARALLEL_MIN_FACTOR => 1,
        0 => idle_cores(),
        n => n,
    }
}

/// Runs `f` with the parallelism of `threads`: on the calling thread when one, else on a scoped
/// pool of `threads` threads that are gone when this returns (serially if the system gives no
/// thread).
pub(super) fn with_threads<R: Send>(threads: usize, f: impl FnOnce(Par) -> R + Send) -> R {
    if threads <= 1 {
        return f(Par::Seq);
    }
    let tasks = Mutex::new(Vec::with_capacity(threads));
    let mut f = Some(f);
    let pooled = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .thread_name(|i| format!("factorization {i}"))
        .build_scoped(
            |thread| {
                let task = worker::own_task();
                tasks.lock().unwrap_or_else(|e| e.into_inner()).push(task);
                thread.run();
            },
            |pool| {
                let f = f.take().expect("called once");
                pool.install(move || f(Par::rayon(threads)))
            },
        );
    for task in tasks.into_inner().unwrap_or_else(|e| e.into_inner()) {
        worker::wait_until_gone(task);
    }
    match pooled {
        Ok(out) => out,
        Err(_) => (f.take().expect("the pool was not built"))(Par::Seq),
    }
}

/// The numeric LDLᵀ of the lower triangle `lower` into `factor` on `threads` threads
/// ([`with_threads`]; `scratch` sized for them): multifrontal on a supernodal analysis, faer's
/// simplicial factorization on a simplicial one (small or sparse factors).
pub(super) fn factorize_ldlt(
    symbolic: &Analysed,
    factor: &mut [f64],
    lower: SparseColMatRef<'_, usize, f64>,
    threads: usize,
    scratch: &mut MemBuffer,
) -> Result<(), LdltError> {
    with_threads(threads, |par| match &symbolic.tree {
        Some(tree) => multifrontal::factorize(symbolic, tree, factor, lower, par),
        None => symbolic
            .factorize_numeric_ldlt(
                factor,
                lower,
                Side::Lower,
                LdltRegularization::default(),
                par,
                MemStack::new(scratch),
                Default::default(),
            )
            .map(|_| ()),
    })
}

/// Solves `A x = rhs` in place with the LDLᵀ `factor` of `symbolic` on `threads` threads: the
/// tree's two sweeps on a supernodal analysis (`multifrontal::solve`), faer's simplicial solve
/// otherwise (`scratch` sized for it).
pub(super) fn solve_ldlt(
    symbolic: &Analysed,
    factor: &[f64],
    rhs: &mut [f64],
    threads: usize,
    scratch: &mut MemBuffer,
) {
    match &symbolic.tree {
        Some(tree) => with_threads(threads, |par| {
            multifrontal::solve(symbolic, tree, factor, rhs, par)
        }),
        None => {
            let n = rhs.len();
            LdltRef::new(&symbolic.symbolic, factor).solve_in_place_with_conj(
                Conj::No,
                MatMut::from_column_major_slice_mut(rhs, n, 1),
                Par::Seq,
                MemStack::new(scratch),
            );
        }
    }
}

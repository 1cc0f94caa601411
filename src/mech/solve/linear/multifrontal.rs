//! The numeric LDLᵀ on faer's supernodal symbolic analysis as a multifrontal factorization
//! (Duff & Reid 1983; Liu 1992, §4) whose sibling subtrees run on separate threads (issue 42
//! item 1: the tree-level parallelism a nested-dissection ordering exposes). Each supernode's
//! front gathers its columns of `A` and its children's update matrices (extend-add), factors its
//! diagonal block (dense LDLᵀ), solves its off-diagonal rows and forms its own update matrix
//! `−L_b D L_bᵀ` in one dense product, which the parent gathers. The factor is stored in faer's
//! supernodal layout, so faer's solve reads it.
//!
//! The arithmetic is fixed by the tree, not by the threads: a front gathers its children in their
//! order whichever finished first, and faer's dense kernels give the same bits on any `Par`; so
//! every thread count gives the same bits (test
//! `factorization_on_two_and_three_threads_gives_the_same_bits_as_on_one`).

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::ldlt::factor::{
    LdltError, LdltRegularization, cholesky_in_place, cholesky_in_place_scratch,
};
use faer::linalg::matmul::triangular::{BlockStructure, matmul};
use faer::linalg::triangular_solve::solve_unit_lower_triangular_in_place;
use faer::reborrow::*;
use faer::sparse::linalg::cholesky::SymbolicCholesky;
use faer::sparse::linalg::cholesky::SymbolicCholeskyRaw;
use faer::sparse::linalg::cholesky::supernodal::SymbolicSupernodalCholesky;
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use faer::{Accum, MatMut, Par};
use rayon::prelude::*;
use std::collections::BTreeMap;
use std::sync::Mutex;

/// Subtrees of fewer flops than this are factorized on the thread that reached them (a task
/// costs microseconds; this is about a tenth of a millisecond of work).
const TASK_FLOPS: f64 = 1e6;

/// Fronts with at least this many rows use the threads inside their dense kernels too.
const PARALLEL_FRONT: usize = 256;

/// faer's symbolic analysis with the multifrontal factorization's tree (None: a simplicial
/// analysis, which faer factorizes).
pub(super) struct Analysed {
    pub(super) symbolic: SymbolicCholesky<usize>,
    pub(super) tree: Option<Tree>,
}

impl std::ops::Deref for Analysed {
    type Target = SymbolicCholesky<usize>;
    fn deref(&self) -> &Self::Target {
        &self.symbolic
    }
}

impl Analysed {
    /// The analysis of the lower triangle `lower`, with its tree.
    pub(super) fn new(
        symbolic: SymbolicCholesky<usize>,
        lower: SymbolicSparseColMatRef<'_, usize>,
    ) -> Self {
        let tree = Tree::new(&symbolic, lower);
        Self { symbolic, tree }
    }
}

/// The supernodal elimination tree: each supernode's children (ascending), the roots, each
/// subtree's flops, and where each lower entry of the matrix goes: per supernode (`gather_ptr`),
/// the entry's index in the matrix's values and its place in the supernode's values.
pub(super) struct Tree {
    children: Vec<Vec<usize>>,
    roots: Vec<usize>,
    flops: Vec<f64>,
    gather_ptr: Vec<usize>,
    gather: Vec<(u32, u32)>,
}
/// A supernode's columns `begin..end` and off-diagonal row pattern.
pub(super) struct Node<'a> {
    pub(super) begin: usize,
    pub(super) end: usize,
    pub(super) pattern: &'a [usize],
}

/// Supernode `s` of a supernodal analysis.
pub(super) fn node(sym: &SymbolicSupernodalCholesky<usize>, s: usize) -> Node<'_> {
    let start = sym.col_ptr_for_row_idx()[s];
    Node {
        begin: sym.supernode_begin()[s],
        end: sym.supernode_end()[s],
        pattern: &sym.row_idx()[start..start + sym.nnz_per_super()[s]],
    }
}

/// The supernodes of a supernodal analysis and the supernode of each column; None for a
/// simplicial analysis.
pub(super) fn supernodes(
    symbolic: &SymbolicCholesky<usize>,
) -> Option<(&SymbolicSupernodalCholesky<usize>, Vec<usize>)> {
    let SymbolicCholeskyRaw::Supernodal(sym) = symbolic.raw() else {
        return None;
    };
    let mut of_column = vec![0; sym.nrows()];
    for s in 0..sym.n_supernodes() {
        let n = node(sym, s);
        of_column[n.begin..n.end].fill(s);
    }
    Some((sym, of_column))
}

impl Tree {
    /// The tree of a supernodal analysis of the lower triangle `lower`; None for a simplicial
    /// one, or where an index does not fit 32 bits.
    fn new(
        symbolic: &SymbolicCholesky<usize>,
        lower: SymbolicSparseColMatRef<'_, usize>,
    ) -> Option<Self> {
        let (sym, of_column) = supernodes(symbolic)?;
        let count = sym.n_supernodes();
        let mut tree = Self {
            children: vec![Vec::new(); count],
            roots: Vec::new(),
            flops: vec![0.0; count],
            gather_ptr: Vec::new(),
            gather: Vec::new(),
        };
        for s in 0..count {
            let n = node(sym, s);
            let (k, m) = ((n.end - n.begin) as f64, n.pattern.len() as f64);
            tree.flops[s] += k * k * (k / 3.0 + m) + m * m * k;
            match n.pattern.first() {
                Some(&row) => {
                    let parent = of_column[row];
                    tree.children[parent].push(s);
                    tree.flops[parent] += tree.flops[s];
                }
                None => tree.roots.push(s),
            }
        }
        tree.gather_map(sym, &of_column, symbolic.perm(), lower)?;
        Some(tree)
    }

    /// Where each lower entry of the matrix goes in the factor: its permuted row and column
    /// (swapped into the lower triangle), the supernode of the column, the row's place there.
    fn gather_map(
        &mut self,
        sym: &SymbolicSupernodalCholesky<usize>,
        of_column: &[usize],
        perm: Option<faer::perm::PermRef<'_, usize>>,
        lower: SymbolicSparseColMatRef<'_, usize>,
    ) -> Option<()> {
        let new_index = |i: usize| perm.map_or(i, |p| p.arrays().1[i]);
        let mut placed: Vec<(usize, u32, u32)> = Vec::with_capacity(lower.row_idx().len());
        for j in 0..lower.ncols() {
            let span = lower.col_ptr()[j]..lower.col_ptr()[j + 1];
            for (e, &i) in span.clone().zip(&lower.row_idx()[span]) {
                if i < j {
                    continue;
                }
                let (a, b) = (new_index(i), new_index(j));
                let (row, col) = (a.max(b), a.min(b));
                let s = of_column[col];
                let n = node(sym, s);
                let rows = n.end - n.begin + n.pattern.len();
                let local = if row < n.end {
                    row - n.begin
                } else {
                    n.end - n.begin + n.pattern.binary_search(&row).ok()?
                };
                let place = (col - n.begin) * rows + local;
                placed.push((s, u32::try_from(e).ok()?, u32::try_from(place).ok()?));
            }
        }
        placed.sort_unstable_by_key(|&(s, _, _)| s);
        self.gather_ptr = vec![0; self.children.len() + 1];
        for &(s, _, _) in &placed {
            self.gather_ptr[s + 1] += 1;
        }
        for s in 0..self.children.len() {
            self.gather_ptr[s + 1] += self.gather_ptr[s];
        }
        self.gather = placed.into_iter().map(|(_, e, p)| (e, p)).collect();
        Some(())
    }
}

/// The LDLᵀ of the lower triangle `lower` (the pattern `tree` was made for) into `factor`
/// (faer's supernodal layout) on the parallelism `par` (module doc); faer's error for a zero
/// pivot, at its permuted index.
pub(super) fn factorize(
    analysed: &Analysed,
    tree: &Tree,
    factor: &mut [f64],
    lower: SparseColMatRef<'_, usize, f64>,
    par: Par,
) -> Result<(), LdltError> {
    let SymbolicCholeskyRaw::Supernodal(sym) = analysed.raw() else {
        unreachable!("a tree exists for supernodal analyses only")
    };
    let a = lower.val();
    let lengths = sym.col_ptr_for_val().windows(2).map(|w| w[1] - w[0]);
    let slots = split_into(factor, lengths);
    let job = Job {
        sym,
        tree,
        a,
        par,
        slots: Mutex::new(slots),
        pool: Mutex::new(BTreeMap::new()),
    };
    job.subtrees(&tree.roots).map(|_| ())
}

/// What every front reads: the analysis, the tree, the matrix's values, the parallelism, and
/// each supernode's factor values, which its front takes.
struct Job<'a, 'v> {
    sym: &'a SymbolicSupernodalCholesky<usize>,
    tree: &'a Tree,
    a: &'a [f64],
    par: Par,
    slots: Mutex<Vec<Option<&'v mut [f64]>>>,
    /// Buffers of finished update matrices, for the next fronts, by capacity.
    pool: Mutex<BTreeMap<usize, Vec<Vec<f64>>>>,
}

/// A front's update matrix: its pattern's lower triangle, column-major, `m × m`.
type Update = Vec<f64>;

impl Job<'_, '_> {
    /// Factorizes the subtrees rooted at `roots`, on separate threads where the parallelism
    /// and their flops allow; their update matrices in their order.
    fn subtrees(&self, roots: &[usize]) -> Result<Vec<Update>, LdltError> {
        let heavy = roots
            .iter()
            .filter(|&&r| self.tree.flops[r] >= TASK_FLOPS)
            .count();
        if heavy >= 2 && self.par.degree() > 1 {
            roots.par_iter().map(|&r| self.subtree(r)).collect()
        } else {
            roots.iter().map(|&r| self.subtree(r)).collect()
        }
    }

    /// Factorizes the subtree rooted at `s`: the children's subtrees, then the front of `s`.
    /// Returns the update matrix of `s`.
    fn subtree(&self, s: usize) -> Result<Update, LdltError> {
        let updates = self.subtrees(&self.tree.children[s])?;
        let own = self.slots.lock().unwrap_or_else(|e| e.into_inner())[s]
            .take()
            .expect("each supernode's front runs once");
        let update = self.front(s, own, &updates);
        updates.into_iter().for_each(|u| self.give_back(u));
        update
    }

    /// The front of `s`: gathers `A`'s columns and the children's `updates` into the
    /// supernode's values `own` and a new update matrix, factorizes and eliminates.
    fn front(&self, s: usize, own: &mut [f64], updates: &[Update]) -> Result<Update, LdltError> {
        let n = node(self.sym, s);
        let (k, m) = (n.end - n.begin, n.pattern.len());
        let children = &self.tree.children[s];
        own.fill(0.0);
        self.gather_columns(s, own);
        let mut update = self.buffer(m * m);
        for (&c, u) in children.iter().zip(updates) {
            extend_add(&n, node(self.sym, c).pattern, u, (own, &mut update), true);
        }
        let par = if k + m >= PARALLEL_FRONT {
            self.par
        } else {
            Par::Seq
        };
        let mut ls = MatMut::from_column_major_slice_mut(own, k + m, k);
        let (mut top, mut bottom) = ls.rb_mut().split_at_row_mut(k);
        factor_block(top.rb_mut(), par).map_err(|e| match e {
            LdltError::ZeroPivot { index } => LdltError::ZeroPivot {
                index: index + n.begin,
            },
        })?;
        solve_unit_lower_triangular_in_place(top.rb(), bottom.rb_mut().transpose_mut(), par);
        if m > 0 {
            // `bottom` is `L_b D` here: kept, then scaled to `L_b`; the update is `−(L_b D) L_bᵀ`.
            let mut kept = self.buffer(m * k);
            let mut w = MatMut::from_column_major_slice_mut(&mut kept, m, k);
            w.copy_from(bottom.rb());
            for j in 0..k {
                let d = top[(j, j)].recip();
                bottom.rb_mut().col_mut(j).iter_mut().for_each(|x| *x *= d);
            }
            matmul(
                MatMut::from_column_major_slice_mut(&mut update, m, m),
                BlockStructure::TriangularLower,
                Accum::Replace,
                w.rb(),
                BlockStructure::Rectangular,
                bottom.rb().transpose(),
                BlockStructure::Rectangular,
                -1.0,
                par,
            );
            self.give_back(kept);
            for (&c, u) in children.iter().zip(updates) {
                extend_add(&n, node(self.sym, c).pattern, u, (own, &mut update), false);
            }
        }
        Ok(update)
    }

    /// A buffer of `len` values from the pool, the smallest that holds them (its values are
    /// whatever they were).
    fn buffer(&self, len: usize) -> Vec<f64> {
        if len == 0 {
            return Vec::new();
        }
        let mut pool = self.pool.lock().unwrap_or_else(|e| e.into_inner());
        let fit = pool
            .range_mut(len..)
            .next()
            .map(|(&size, list)| (size, list.pop()));
        let mut b = match fit {
            Some((size, Some(b))) => {
                if pool.get(&size).is_some_and(Vec::is_empty) {
                    pool.remove(&size);
                }
                b
            }
            _ => Vec::new(),
        };
        drop(pool);
        b.resize(len, 0.0);
        b
    }

    /// Returns a buffer to the pool.
    fn give_back(&self, b: Vec<f64>) {
        if b.capacity() > 0 {
            let mut pool = self.pool.lock().unwrap_or_else(|e| e.into_inner());
            pool.entry(b.capacity()).or_default().push(b);
        }
    }

    /// Adds the matrix's lower entries in the columns of `s` to its values (the tree's map).
    fn gather_columns(&self, s: usize, own: &mut [f64]) {
        let span = self.tree.gather_ptr[s]..self.tree.gather_ptr[s + 1];
        for &(e, place) in &self.tree.gather[span] {
            own[place as usize] += self.a[e as usize];
        }
    }
}

/// `whole` cut into consecutive slices of `lengths`, each in a slot a task takes it from (one
/// supernode's part of the factor or of the solution).
fn split_into(whole: &mut [f64], lengths: impl Iterator<Item = usize>) -> Vec<Option<&mut [f64]>> {
    let mut rest = whole;
    lengths
        .map(|len| {
            let (own, tail) = std::mem::take(&mut rest).split_at_mut(len);
            rest = tail;
            Some(own)
        })
        .collect()
}

/// Adds a child's update matrix `u` over its pattern `child` into the front of `n`: with
/// `columns` its columns in the front's columns to the supernode's values `own`, else the
/// others to the front's update matrix. Rows whose places follow each other are added as one
/// run.
fn extend_add(
    n: &Node<'_>,
    child: &[usize],
    u: &[f64],
    (own, update): (&mut [f64], &mut [f64]),
    columns: bool,
) {
    let k = n.end - n.begin;
    let (rows, m) = (k + n.pattern.len(), n.pattern.len());
    // The child's pattern lies in the front's columns and pattern (both ascending): merge.
    let mut local = Vec::with_capacity(child.len());
    let mut at = 0;
    for &r in child {
        if r < n.end {
            local.push(r - n.begin);
        } else {
            while n.pattern[at] != r {
                at += 1;
            }
            local.push(k + at);
        }
    }
    // Runs of consecutive places (start in the child, length), never across the block's edge.
    let mut runs: Vec<(usize, usize)> = Vec::new();
    for (p, &l) in local.iter().enumerate() {
        match runs.last_mut() {
            Some((start, len)) if local[*start] + *len == l && (l != k) => *len += 1,
            _ => runs.push((p, 1)),
        }
    }
    let mc = child.len();
    // The child's columns in the front's columns come first (ascending places).
    let split = local.partition_point(|&l| l < k);
    let range = if columns { 0..split } else { split..mc };
    let mut first_run = 0;
    for q in range {
        while runs[first_run].0 + runs[first_run].1 <= q {
            first_run += 1;
        }
        let gj = local[q];
        let column = &u[q * mc..(q + 1) * mc];
        let (target, shift) = if gj < k {
            (&mut own[gj * rows..(gj + 1) * rows], 0)
        } else {
            (&mut update[(gj - k) * m..(gj - k + 1) * m], k)
        };
        for &(start, len) in &runs[first_run..] {
            let from = start.max(q);
            let to = start + len;
            let place = local[from] - shift;
            let dst = &mut target[place..place + (to - from)];
            for (d, v) in dst.iter_mut().zip(&column[from..to]) {
                *d += v;
            }
        }
    }
}

/// Solves `A x = rhs` in place with the factor `factor` of [`factorize`] on the parallelism
/// `par`: `L y = P b` by the tree (each subtree passes its contributions to the rows of its
/// root's pattern up, as the factorization passes update matrices), `D z = y`, then `Lᵀ w = z`
/// from the roots down (each front reads its pattern's values from its parent), `x = Pᵀ w`.
/// The sums are fixed by the tree, so every thread count gives the same bits.
pub(super) fn solve(analysed: &Analysed, tree: &Tree, factor: &[f64], rhs: &mut [f64], par: Par) {
    let SymbolicCholeskyRaw::Supernodal(sym) = analysed.raw() else {
        unreachable!("a tree exists for supernodal analyses only")
    };
    let perm = analysed.perm();
    let forward_index = |i: usize| perm.map_or(i, |p| p.arrays().0[i]);
    let b: Vec<f64> = (0..rhs.len()).map(|i| rhs[forward_index(i)]).collect();
    let mut w = vec![0.0; rhs.len()];
    let lengths = (0..sym.n_supernodes()).map(|s| {
        let n = node(sym, s);
        n.end - n.begin
    });
    let slots = split_into(&mut w, lengths);
    let sweep = Sweep {
        sym,
        tree,
        factor,
        b: &b,
        par,
        y: Mutex::new(vec![None; sym.n_supernodes()]),
        slots: Mutex::new(slots),
    };
    let heavy = |r: &usize| tree.flops[*r] >= TASK_FLOPS;
    let parallel = par.degree() > 1 && tree.roots.iter().filter(|r| heavy(r)).count() >= 2;
    let each = |r: &usize| {
        sweep.forward(*r);
        sweep.backward(*r, Vec::new());
    };
    if parallel {
        tree.roots.par_iter().for_each(each);
    } else {
        tree.roots.iter().for_each(each);
    }
    drop(sweep);
    for (i, x) in w.into_iter().enumerate() {
        rhs[forward_index(i)] = x;
    }
}

/// What the two sweeps of [`solve`] share: the analysis, the factor, the permuted right-hand
/// side, each supernode's `z = D⁻¹ y` once its forward step is done, and its slice of the answer.
struct Sweep<'a, 'w> {
    sym: &'a SymbolicSupernodalCholesky<usize>,
    tree: &'a Tree,
    factor: &'a [f64],
    b: &'a [f64],
    par: Par,
    y: Mutex<Vec<Option<Vec<f64>>>>,
    slots: Mutex<Vec<Option<&'w mut [f64]>>>,
}

impl Sweep<'_, '_> {
    /// Whether the children of `s` go to separate threads.
    fn split(&self, s: usize) -> bool {
        let heavy = self.tree.children[s]
            .iter()
            .filter(|&&c| self.tree.flops[c] >= TASK_FLOPS)
            .count();
        heavy >= 2 && self.par.degree() > 1
    }

    /// The supernode's values as a matrix: `k + m` rows, `k` columns.
    fn values(&self, s: usize) -> faer::MatRef<'_, f64> {
        let ptr = self.sym.col_ptr_for_val();
        let n = node(self.sym, s);
        let (k, m) = (n.end - n.begin, n.pattern.len());
        faer::MatRef::from_column_major_slice(&self.factor[ptr[s]..ptr[s + 1]], k + m, k)
    }

    /// `L y = b` over the subtree of `s`: stores `z_s = D⁻¹ y_s` and returns the subtree's
    /// contributions to the rows of the pattern of `s`.
    fn forward(&self, s: usize) -> Vec<f64> {
        let children = &self.tree.children[s];
        let ups: Vec<Vec<f64>> = if self.split(s) {
            children.par_iter().map(|&c| self.forward(c)).collect()
        } else {
            children.iter().map(|&c| self.forward(c)).collect()
        };
        let n = node(self.sym, s);
        let k = n.end - n.begin;
        let mut ys = self.b[n.begin..n.end].to_vec();
        let mut up = vec![0.0; n.pattern.len()];
        for (&c, u) in children.iter().zip(&ups) {
            let mut at = 0;
            for (&r, v) in node(self.sym, c).pattern.iter().zip(u) {
                if r < n.end {
                    ys[r - n.begin] += v;
                } else {
                    while n.pattern[at] != r {
                        at += 1;
                    }
                    up[at] += v;
                }
            }
        }
        let l = self.values(s);
        let (top, bottom) = l.split_at_row(k);
        solve_unit_lower_triangular_in_place(
            top,
            MatMut::from_column_major_slice_mut(&mut ys, k, 1),
            Par::Seq,
        );
        if !up.is_empty() {
            faer::linalg::matmul::matmul(
                MatMut::from_column_major_slice_mut(&mut up, n.pattern.len(), 1),
                Accum::Add,
                bottom,
                faer::MatRef::from_column_major_slice(&ys, k, 1),
                -1.0,
                Par::Seq,
            );
        }
        for (j, y) in ys.iter_mut().enumerate() {
            *y /= top[(j, j)];
        }
        self.y.lock().unwrap_or_else(|e| e.into_inner())[s] = Some(ys);
        up
    }

    /// `Lᵀ w = z` over the subtree of `s`, given `w` at the rows of its pattern.
    fn backward(&self, s: usize, above: Vec<f64>) {
        let n = node(self.sym, s);
        let k = n.end - n.begin;
        let mut ws = self.y.lock().unwrap_or_else(|e| e.into_inner())[s]
            .take()
            .expect("the forward sweep stored it");
        let l = self.values(s);
        let (top, bottom) = l.split_at_row(k);
        if !above.is_empty() {
            faer::linalg::matmul::matmul(
                MatMut::from_column_major_slice_mut(&mut ws, k, 1),
                Accum::Add,
                bottom.transpose(),
                faer::MatRef::from_column_major_slice(&above, above.len(), 1),
                -1.0,
                Par::Seq,
            );
        }
        faer::linalg::triangular_solve::solve_unit_upper_triangular_in_place(
            top.transpose(),
            MatMut::from_column_major_slice_mut(&mut ws, k, 1),
            Par::Seq,
        );
        let down = |c: usize| -> Vec<f64> {
            let mut at = 0;
            node(self.sym, c)
                .pattern
                .iter()
                .map(|&r| {
                    if r < n.end {
                        ws[r - n.begin]
                    } else {
                        while n.pattern[at] != r {
                            at += 1;
                        }
                        above[at]
                    }
                })
                .collect()
        };
        let children = &self.tree.children[s];
        let parts: Vec<(usize, Vec<f64>)> = children.iter().map(|&c| (c, down(c))).collect();
        self.slots.lock().unwrap_or_else(|e| e.into_inner())[s]
            .take()
            .expect("each supernode's answer is written once")
            .copy_from_slice(&ws);
        if self.split(s) {
            parts.into_par_iter().for_each(|(c, v)| self.backward(c, v));
        } else {
            parts.into_iter().for_each(|(c, v)| self.backward(c, v));
        }
    }
}

/// The dense LDLᵀ of a front's diagonal block in place (`D` on the diagonal, unit `L` below,
/// zeros above, as faer's supernodal layout holds it).
fn factor_block(mut top: MatMut<'_, f64>, par: Par) -> Result<(), LdltError> {
    let k = top.nrows();
    let mut scratch = MemBuffer::new(cholesky_in_place_scratch::<f64>(k, par, Default::default()));
    cholesky_in_place(
        top.rb_mut(),
        LdltRegularization::default(),
        par,
        MemStack::new(&mut scratch),
        Default::default(),
    )?;
    for j in 0..k {
        for i in 0..j {
            top[(i, j)] = 0.0;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use faer::Side;
    use faer::sparse::linalg::SupernodalThreshold;
    use faer::sparse::linalg::cholesky::{
        CholeskySymbolicParams, SymmetricOrdering, factorize_symbolic_cholesky,
    };
    use faer::sparse::{SparseColMat, Triplet};

    /// The lower triangle of a symmetric matrix on an `n × n` grid of 3-DOF nodes, each node
    /// coupled to its 8 neighbours: diagonally dominant, with a negative diagonal entry every
    /// 5th DOF (an indefinite matrix the unpivoted LDLᵀ still takes: a compressed film's).
    fn grid(n: usize) -> SparseColMat<usize, f64> {
        let dofs = 3 * n * n;
        let mut entries = Vec::new();
        for j in 0..n {
            for i in 0..n {
                let v = j * n + i;
                for (di, dj) in [(0, 0), (1, 0), (0, 1), (1, 1), (-1, 1)] {
                    let (i2, j2) = (i as i64 + di, j as i64 + dj);
                    if i2 < 0 || j2 < 0 || i2 >= n as i64 || j2 >= n as i64 {
                        continue;
                    }
                    let w = j2 as usize * n + i2 as usize;
                    for a in 0..3 {
                        for b in 0..3 {
                            let (r, c) = (3 * w + a, 3 * v + b);
                            if r < c {
                                continue;
                            }
                            let value = if r == c {
                                if r % 5 == 0 {
                                    -40.0
                                } else {
                                    40.0 + (r % 7) as f64
                                }
                            } else {
                                -1.0 + 0.1 * ((r + 2 * c) % 5) as f64
                            };
                            entries.push(Triplet::new(r, c, value));
                        }
                    }
                }
            }
        }
        SparseColMat::try_new_from_triplets(dofs, dofs, &entries).unwrap()
    }

    /// faer's AMD analysis of `a`, forced supernodal, with its tree.
    fn analysed(a: &SparseColMat<usize, f64>) -> Analysed {
        let params = CholeskySymbolicParams {
            supernodal_flop_ratio_threshold: SupernodalThreshold::FORCE_SUPERNODAL,
            ..Default::default()
        };
        let symbolic =
            factorize_symbolic_cholesky(a.symbolic(), Side::Lower, SymmetricOrdering::Amd, params)
                .unwrap();
        Analysed::new(symbolic, a.symbolic())
    }

    /// faer's supernodal analysis of `a` (forced supernodal), its multifrontal factor on
    /// `threads` threads, and faer's own factor.
    fn factors(a: &SparseColMat<usize, f64>, threads: usize) -> (Vec<f64>, Vec<f64>) {
        let analysed = analysed(a);
        let tree = analysed.tree.as_ref().expect("a supernodal analysis");
        let symbolic = &analysed.symbolic;
        let len = symbolic.len_val();
        let req = symbolic.factorize_numeric_ldlt_scratch::<f64>(Par::Seq, Default::default());
        let mut scratch = MemBuffer::new(req);
        let mut ours = vec![0.0; len];
        super::super::pool::with_threads(threads, |par| {
            factorize(&analysed, tree, &mut ours, a.as_ref(), par)
        })
        .unwrap();
        let mut theirs = vec![0.0; len];
        symbolic
            .factorize_numeric_ldlt(
                &mut theirs,
                a.as_ref(),
                Side::Lower,
                LdltRegularization::default(),
                Par::Seq,
                MemStack::new(&mut scratch),
                Default::default(),
            )
            .unwrap();
        (ours, theirs)
    }

    #[test]
    fn multifrontal_factor_equals_faers_left_looking_factor_to_rounding() {
        let a = grid(30);
        let (ours, theirs) = factors(&a, 1);
        let scale = theirs.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        let worst = ours
            .iter()
            .zip(&theirs)
            .fold(0.0_f64, |m, (x, y)| m.max((x - y).abs()));
        assert!(
            worst <= 1e-12 * scale,
            "largest difference {worst:e} of {scale:e}"
        );
    }

    #[test]
    fn multifrontal_factor_has_the_same_bits_on_two_threads_as_on_one() {
        let a = grid(40);
        let (one, _) = factors(&a, 1);
        let (two, _) = factors(&a, 2);
        let differ = one
            .iter()
            .zip(&two)
            .filter(|(x, y)| x.to_bits() != y.to_bits())
            .count();
        assert_eq!(differ, 0, "{differ} of {} values differ", one.len());
    }

    /// The tree's solve and faer's on the same factor, on `threads` threads.
    fn solves(n: usize, threads: usize) -> (Vec<f64>, Vec<f64>) {
        let a = grid(n);
        let analysed = analysed(&a);
        let tree = analysed.tree.as_ref().expect("a supernodal analysis");
        let mut factor = vec![0.0; analysed.len_val()];
        factorize(&analysed, tree, &mut factor, a.as_ref(), Par::Seq).unwrap();
        let b: Vec<f64> = (0..a.ncols()).map(|i| 1.0 + (i % 11) as f64).collect();
        let mut ours = b.clone();
        super::super::pool::with_threads(threads, |par| {
            solve(&analysed, tree, &factor, &mut ours, par)
        });
        let mut theirs = b;
        let req = analysed.solve_in_place_scratch::<f64>(1, Par::Seq);
        let mut scratch = MemBuffer::new(req);
        faer::sparse::linalg::cholesky::LdltRef::new(&analysed.symbolic, &factor)
            .solve_in_place_with_conj(
                faer::Conj::No,
                MatMut::from_column_major_slice_mut(&mut theirs, a.ncols(), 1),
                Par::Seq,
                MemStack::new(&mut scratch),
            );
        (ours, theirs)
    }

    #[test]
    fn tree_solve_equals_faers_solve_to_rounding_with_the_same_bits_on_two_threads() {
        let (one, theirs) = solves(40, 1);
        let scale = theirs.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        let worst = one
            .iter()
            .zip(&theirs)
            .fold(0.0_f64, |m, (x, y)| m.max((x - y).abs()));
        assert!(
            worst <= 1e-12 * scale,
            "largest difference {worst:e} of {scale:e}"
        );
        let (two, _) = solves(40, 2);
        let differ = one
            .iter()
            .zip(&two)
            .filter(|(x, y)| x.to_bits() != y.to_bits())
            .count();
        assert_eq!(differ, 0, "{differ} values differ on two threads");
    }
}

//! Fill-reducing orderings of a symmetric pattern: faer's approximate minimum degree (AMD) and a
//! nested dissection written for meshes (issue 42 item 2).
//!
//! Nested dissection (George 1973): cut the graph of the matrix by a small vertex separator
//! into two halves with no edge between them, order each half recursively, then the separator
//! last. On a 2-D mesh of `n` DOFs the factor then holds `O(n log n)` values and costs
//! `O(n^{3/2})` operations, and the last separators are the large dense blocks that a parallel
//! dense kernel works on.
//!
//! * The graph is first compressed: consecutive DOFs with the same closed neighbourhood (the
//!   three DOFs of a free node) become one vertex of that weight, so that no separator splits a
//!   node and the work shrinks threefold.
//! * A separator is a level of a breadth-first level structure rooted at a pseudo-peripheral
//!   vertex (George–Liu): the level whose weight sum crosses half the part's, kept only where
//!   it touches the next level (the level's other vertices join the first half). Among the
//!   levels whose halves stay within [`BALANCE`], the one with the smallest separator is taken.
//! * Parts of at most [`LEAF_WEIGHT`] DOFs are ordered by faer's AMD; a part of several
//!   connected components is split into them, each ordered on its own.

use faer::Side;
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::perm::PermRef;
use faer::sparse::linalg::SupernodalThreshold;
use faer::sparse::linalg::amd;
use faer::sparse::linalg::cholesky::{
    CholeskySymbolicParams, SymbolicCholesky, SymmetricOrdering, factorize_symbolic_cholesky,
};
use faer::sparse::{FaerError, SymbolicSparseColMatRef};

/// Which fill-reducing ordering the symbolic analysis uses.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum FillOrdering {
    /// Nested dissection from [`NESTED_DISSECTION_MIN_DOFS`] equations up, else AMD.
    #[default]
    Auto,
    /// faer's approximate minimum degree.
    Amd,
    /// Nested dissection ([`nested_dissection`]).
    NestedDissection,
}

/// Equations from which [`FillOrdering::Auto`] takes nested dissection.
pub const NESTED_DISSECTION_MIN_DOFS: usize = 100_000;

/// Parts of at most this many DOFs are ordered by AMD instead of being cut further.
pub const LEAF_WEIGHT: usize = 600;

/// Separator levels are considered while the first half holds this share of the weight or
/// more, and at most one minus it.
pub const BALANCE: f64 = 0.35;

impl FillOrdering {
    /// Whether a system of `n` equations is ordered by nested dissection.
    pub fn dissects(self, n: usize) -> bool {
        match self {
            FillOrdering::Auto => n >= NESTED_DISSECTION_MIN_DOFS,
            FillOrdering::Amd => false,
            FillOrdering::NestedDissection => true,
        }
    }
}

/// The symmetric graph of a pattern (one triangle or both), in compressed rows, without the
/// diagonal.
struct Graph {
    start: Vec<usize>,
    adjacent: Vec<u32>,
    /// DOFs each vertex stands for.
    weight: Vec<u32>,
}

impl Graph {
    fn neighbours(&self, v: usize) -> &[u32] {
        &self.adjacent[self.start[v]..self.start[v + 1]]
    }

    /// Both triangles of `pattern` without its diagonal, rows sorted and without duplicates.
    fn of_pattern(pattern: SymbolicSparseColMatRef<'_, usize>) -> Self {
        let n = pattern.ncols();
        let mut degree = vec![0usize; n + 1];
        for j in 0..n {
            for i in pattern.row_idx_of_col(j) {
                if i != j {
                    degree[i] += 1;
                    degree[j] += 1;
                }
            }
        }
        let mut start = vec![0usize; n + 1];
        for v in 0..n {
            start[v + 1] = start[v] + degree[v];
        }
        let mut fill = start.clone();
        let mut adjacent = vec![0u32; start[n]];
        for j in 0..n {
            for i in pattern.row_idx_of_col(j) {
                if i != j {
                    adjacent[fill[i]] = j as u32;
                    fill[i] += 1;
                    adjacent[fill[j]] = i as u32;
                    fill[j] += 1;
                }
            }
        }
        Self::sorted(start, adjacent, vec![1; n])
    }

    /// Sorts each row and drops duplicates (a full pattern gives every edge twice).
    fn sorted(start: Vec<usize>, mut adjacent: Vec<u32>, weight: Vec<u32>) -> Self {
        let n = weight.len();
        let mut new_start = Vec::with_capacity(n + 1);
        new_start.push(0);
        let mut end = 0;
        for v in 0..n {
            let row = &mut adjacent[start[v]..start[v + 1]];
            row.sort_unstable();
            let mut last = u32::MAX;
            for k in start[v]..start[v + 1] {
                let w = adjacent[k];
                if w != last {
                    adjacent[end] = w;
                    end += 1;
                    last = w;
                }
            }
            new_start.push(end);
        }
        adjacent.truncate(end);
        Self {
            start: new_start,
            adjacent,
            weight,
        }
    }

    /// Groups consecutive vertices with the same closed neighbourhood; returns the graph of the
    /// groups and each group's first vertex (then one past the last).
    fn compressed(&self) -> (Self, Vec<usize>) {
        let n = self.weight.len();
        let closed = |v: usize, out: &mut Vec<u32>| {
            out.clear();
            out.extend_from_slice(self.neighbours(v));
            let at = out.partition_point(|&w| (w as usize) < v);
            out.insert(at, v as u32);
        };
        let (mut a, mut b) = (Vec::new(), Vec::new());
        let mut first = vec![0];
        for v in 1..n {
            closed(v - 1, &mut a);
            closed(v, &mut b);
            if a != b {
                first.push(v);
            }
        }
        first.push(n);
        let groups = first.len() - 1;
        let mut group_of = vec![0u32; n];
        for g in 0..groups {
            group_of[first[g]..first[g + 1]].fill(g as u32);
        }
        let mut start = vec![0usize; groups + 1];
        let mut adjacent = Vec::new();
        for g in 0..groups {
            // Members share their neighbourhood: the first's is the group's.
            adjacent.extend(
                self.neighbours(first[g])
                    .iter()
                    .map(|&w| group_of[w as usize])
                    .filter(|&h| h as usize != g),
            );
            start[g + 1] = adjacent.len();
        }
        let weight = (0..groups)
            .map(|g| (first[g + 1] - first[g]) as u32)
            .collect();
        (Self::sorted(start, adjacent, weight), first)
    }
}

/// Nested dissection of the symmetric pattern `pattern` (one triangle or both): the
/// elimination order (`order[k]` is the equation eliminated `k`-th) and its inverse.
pub fn nested_dissection(pattern: SymbolicSparseColMatRef<'_, usize>) -> (Vec<usize>, Vec<usize>) {
    let n = pattern.ncols();
    let (graph, first) = Graph::of_pattern(pattern).compressed();
    let mut work = Dissection::new(&graph);
    let all: Vec<u32> = (0..graph.weight.len() as u32).collect();
    // A post-order: each part's halves, then its separator.
    let mut tasks = vec![Task::Cut(all)];
    while let Some(task) = tasks.pop() {
        match task {
            Task::Place(separator) => work.order.extend(separator),
            Task::Cut(part) => match work.cut(&part) {
                Cut::Leaf => work.order_leaf(&part),
                Cut::Split(a, b, separator) => {
                    tasks.push(Task::Place(separator));
                    tasks.push(Task::Cut(b));
                    tasks.push(Task::Cut(a));
                }
                Cut::Components(parts) => tasks.extend(parts.into_iter().rev().map(Task::Cut)),
            },
        }
    }
    let groups = work.order;
    let order: Vec<usize> = groups
        .iter()
        .flat_map(|&g| first[g as usize]..first[g as usize + 1])
        .collect();
    let mut inverse = vec![0; n];
    for (k, &v) in order.iter().enumerate() {
        inverse[v] = k;
    }
    (order, inverse)
}

/// Work left in a dissection: a part to cut, or a separator to place.
enum Task {
    Cut(Vec<u32>),
    Place(Vec<u32>),
}

/// A part cut in two halves and a separator, a part of several connected components (each
/// ordered on its own), or a leaf.
enum Cut {
    Leaf,
    Split(Vec<u32>, Vec<u32>, Vec<u32>),
    Components(Vec<Vec<u32>>),
}

/// The work arrays of a dissection: the part each vertex is in (a stamp), its level, and the
/// order of the leaves so far.
struct Dissection<'a> {
    graph: &'a Graph,
    part: Vec<u32>,
    level: Vec<u32>,
    stamp: u32,
    order: Vec<u32>,
}

impl<'a> Dissection<'a> {
    fn new(graph: &'a Graph) -> Self {
        let n = graph.weight.len();
        Self {
            graph,
            part: vec![0; n],
            level: vec![0; n],
            stamp: 0,
            order: Vec::with_capacity(n),
        }
    }

    fn weight(&self, vertices: &[u32]) -> usize {
        vertices
            .iter()
            .map(|&v| self.graph.weight[v as usize] as usize)
            .sum()
    }

    /// Breadth-first levels of the part stamped `self.stamp` from `root`: the vertices in visit
    /// order and where each level starts; `self.level` holds each visited vertex's level.
    fn levels(&mut self, root: u32) -> (Vec<u32>, Vec<usize>) {
        let mut visited = vec![root];
        let mut starts = vec![0];
        self.part[root as usize] = self.stamp + 1;
        self.level[root as usize] = 0;
        let (mut head, mut depth) = (0, 0);
        // Level `d` is `visited[starts[d]..starts[d + 1]]`.
        while head < visited.len() {
            let end = visited.len();
            starts.push(end);
            depth += 1;
            for k in head..end {
                for &w in self.graph.neighbours(visited[k] as usize) {
                    if self.part[w as usize] == self.stamp {
                        self.part[w as usize] = self.stamp + 1;
                        self.level[w as usize] = depth;
                        visited.push(w);
                    }
                }
            }
            head = end;
        }
        // Give the part its stamp back for the next search.
        for &v in &visited {
            self.part[v as usize] = self.stamp;
        }
        (visited, starts)
    }

    /// Splits `part` by a level separator, or says it is a leaf.
    fn cut(&mut self, part: &[u32]) -> Cut {
        if self.weight(part) <= LEAF_WEIGHT || part.len() < 3 {
            return Cut::Leaf;
        }
        self.stamp += 2;
        for &v in part {
            self.part[v as usize] = self.stamp;
        }
        let (visited, starts) = self.pseudo_peripheral(part[0]);
        if visited.len() < part.len() {
            return Cut::Components(self.components(part));
        }
        if starts.len() < 4 {
            return Cut::Leaf;
        }
        // The structures from both ends of the pseudo-diameter cut across it at different
        // places: the smaller separator wins.
        let (root, far) = (visited[0], visited[visited.len() - 1]);
        let (k, size) = self.best_level(&visited, &starts);
        let (other, other_starts) = self.levels(far);
        let (k_far, size_far) = self.best_level(&other, &other_starts);
        if size_far < size {
            return self.split_at(&other, &other_starts, k_far);
        }
        let (visited, starts) = self.levels(root);
        self.split_at(&visited, &starts, k)
    }

    /// The connected components of the part stamped `self.stamp` (in one sweep: a model with
    /// many separate pieces costs no more than one).
    fn components(&mut self, part: &[u32]) -> Vec<Vec<u32>> {
        let mut components = Vec::new();
        for &root in part {
            if self.part[root as usize] != self.stamp {
                continue;
            }
            self.part[root as usize] = self.stamp + 1;
            let mut component = vec![root];
            let mut head = 0;
            while head < component.len() {
                let v = component[head] as usize;
                head += 1;
                for &w in self.graph.neighbours(v) {
                    if self.part[w as usize] == self.stamp {
                        self.part[w as usize] = self.stamp + 1;
                        component.push(w);
                    }
                }
            }
            components.push(component);
        }
        components
    }

    /// Repeated level structures from a vertex of least degree in the last level, while the
    /// depth grows (at most a few times): the last structure.
    fn pseudo_peripheral(&mut self, start: u32) -> (Vec<u32>, Vec<usize>) {
        let mut root = start;
        let (mut visited, mut starts) = self.levels(root);
        for _ in 0..6 {
            let last = &visited[starts[starts.len() - 2]..];
            let candidate = *last
                .iter()
                .min_by_key(|&&v| self.graph.neighbours(v as usize).len())
                .expect("a level is not empty");
            if candidate == root {
                break;
            }
            let (v2, s2) = self.levels(candidate);
            if s2.len() <= starts.len() {
                break;
            }
            root = candidate;
            (visited, starts) = (v2, s2);
        }
        // Every visited vertex keeps its level from the structure returned.
        self.levels(root)
    }

    /// Among the levels that leave each half at least [`BALANCE`] of the weight, the one whose
    /// separator (its vertices touching the next level) weighs least, and that weight (else
    /// the median level).
    fn best_level(&self, visited: &[u32], starts: &[usize]) -> (usize, usize) {
        let total = self.weight(visited) as f64;
        let levels = starts.len() - 1;
        let (mut below, mut best, mut median) = (0.0, None::<(usize, usize)>, None);
        for k in 1..levels - 1 {
            below += self.weight(&visited[starts[k - 1]..starts[k]]) as f64;
            let here = self.weight(&visited[starts[k]..starts[k + 1]]) as f64;
            if median.is_none() && below + here >= 0.5 * total {
                median = Some(k);
            }
            if below >= BALANCE * total && total - below - here >= BALANCE * total {
                let size = self.separator_weight(&visited[starts[k]..starts[k + 1]], k as u32);
                if best.is_none_or(|(_, s)| size < s) {
                    best = Some((k, size));
                }
            }
        }
        best.unwrap_or_else(|| {
            let k = median.unwrap_or(levels / 2);
            (
                k,
                self.separator_weight(&visited[starts[k]..starts[k + 1]], k as u32),
            )
        })
    }

    /// Splits the level structure at level `k`: the levels before and the vertices of level `k`
    /// not touching level `k + 1`, the levels after, and the separator.
    fn split_at(&self, visited: &[u32], starts: &[usize], k: usize) -> Cut {
        let mut a = visited[..starts[k]].to_vec();
        let mut separator = Vec::new();
        for &v in &visited[starts[k]..starts[k + 1]] {
            if self.touches_next(v, k as u32) {
                separator.push(v);
            } else {
                a.push(v);
            }
        }
        Cut::Split(a, visited[starts[k + 1]..].to_vec(), separator)
    }

    fn touches_next(&self, v: u32, k: u32) -> bool {
        self.graph
            .neighbours(v as usize)
            .iter()
            .any(|&w| self.part[w as usize] == self.stamp && self.level[w as usize] == k + 1)
    }

    fn separator_weight(&self, level: &[u32], k: u32) -> usize {
        level
            .iter()
            .filter(|&&v| self.touches_next(v, k))
            .map(|&v| self.graph.weight[v as usize] as usize)
            .sum()
    }

    /// Appends the AMD order of the subgraph `part` induces.
    fn order_leaf(&mut self, part: &[u32]) {
        if part.len() < 3 {
            self.order.extend_from_slice(part);
            return;
        }
        self.stamp += 2;
        for (k, &v) in part.iter().enumerate() {
            self.part[v as usize] = self.stamp;
            self.level[v as usize] = k as u32;
        }
        let m = part.len();
        let mut col_ptr = Vec::with_capacity(m + 1);
        let mut rows = Vec::new();
        col_ptr.push(0);
        for &v in part {
            let first = rows.len();
            for &w in self.graph.neighbours(v as usize) {
                if self.part[w as usize] == self.stamp {
                    rows.push(self.level[w as usize] as usize);
                }
            }
            rows[first..].sort_unstable();
            col_ptr.push(rows.len());
        }
        let nnz = rows.len();
        let local = SymbolicSparseColMatRef::new_checked(m, m, &col_ptr, None, &rows);
        let (mut perm, mut inverse) = (vec![0usize; m], vec![0usize; m]);
        let mut buffer = MemBuffer::new(amd::order_maybe_unsorted_scratch::<usize>(m, nnz));
        let ordered = amd::order_maybe_unsorted(
            &mut perm,
            &mut inverse,
            local,
            amd::Control::default(),
            MemStack::new(&mut buffer),
        );
        match ordered {
            Ok(_) => self.order.extend(perm.iter().map(|&k| part[k])),
            Err(_) => self.order.extend_from_slice(part),
        }
    }
}

/// The symbolic Cholesky analysis of the lower triangle `lower` under `ordering`.
pub(super) fn analyse(
    lower: SymbolicSparseColMatRef<'_, usize>,
    ordering: FillOrdering,
) -> Result<SymbolicCholesky<usize>, FaerError> {
    analyse_with(lower, ordering, Default::default())
}

/// [`analyse`], supernodal whatever the size (the frontal LU's tree).
pub(super) fn analyse_supernodal(
    lower: SymbolicSparseColMatRef<'_, usize>,
    ordering: FillOrdering,
) -> Result<SymbolicCholesky<usize>, FaerError> {
    let params = CholeskySymbolicParams {
        supernodal_flop_ratio_threshold: SupernodalThreshold::FORCE_SUPERNODAL,
        ..Default::default()
    };
    analyse_with(lower, ordering, params)
}

/// The supernodal analysis of `lower` under the permutation `perm` an earlier analysis of it
/// chose (None: the identity).
pub(super) fn analyse_supernodal_with(
    lower: SymbolicSparseColMatRef<'_, usize>,
    perm: Option<PermRef<'_, usize>>,
) -> Result<SymbolicCholesky<usize>, FaerError> {
    let params = CholeskySymbolicParams {
        supernodal_flop_ratio_threshold: SupernodalThreshold::FORCE_SUPERNODAL,
        ..Default::default()
    };
    let ordering = perm.map_or(SymmetricOrdering::Identity, SymmetricOrdering::Custom);
    factorize_symbolic_cholesky(lower, Side::Lower, ordering, params)
}

fn analyse_with(
    lower: SymbolicSparseColMatRef<'_, usize>,
    ordering: FillOrdering,
    params: CholeskySymbolicParams<'_>,
) -> Result<SymbolicCholesky<usize>, FaerError> {
    if !ordering.dissects(lower.ncols()) {
        return factorize_symbolic_cholesky(lower, Side::Lower, SymmetricOrdering::Amd, params);
    }
    let (order, inverse) = nested_dissection(lower);
    let perm = PermRef::new_checked(&order, &inverse, lower.ncols());
    factorize_symbolic_cholesky(lower, Side::Lower, SymmetricOrdering::Custom(perm), params)
}

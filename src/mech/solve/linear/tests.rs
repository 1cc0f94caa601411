use super::*;
use crate::mech::Model;

/// A free 0.1 m square (two triangles, nodes 0..3) whose node 0 is fixed in x, y, z: nine
/// equations, numbered node 1 (x, y, z), node 2, node 3.
fn system(lower_only: bool) -> System {
    let model = Model::from_json(
        r#"{ "name": "Sq", "nodes": [[0,0,0], [0.1,0,0], [0.1,0.1,0], [0,0.1,0]],
             "triangles": [[0,1,2], [0,2,3]],
             "material": { "youngs_modulus": 1e9, "poisson_ratio": 0.43, "thickness": 250e-6,
                           "prestress": [5e5, 5e5, 0] },
             "supports": [{ "node": 0, "fixed": ["x", "y", "z"] }, { "node": 1, "fixed": ["y", "z"] },
                          { "node": 3, "fixed": ["z"] }] }"#,
    )
    .unwrap();
    System::new(&model, lower_only).unwrap()
}

/// Matrix values with `entries` (row, column, value) and zeros elsewhere.
fn values(system: &System, entries: &[(usize, usize, f64)]) -> Vec<f64> {
    let pattern = system.pattern();
    let mut v = vec![0.0; system.nonzeros()];
    for &(i, j, x) in entries {
        let rows = pattern.row_idx_of_col_raw(j);
        let k = rows
            .iter()
            .position(|&r| r == i)
            .expect("entry in the pattern");
        v[pattern.col_ptr()[j] + k] += x;
    }
    v
}

fn solve(lower_only: bool, entries: &[(usize, usize, f64)]) -> Result<Vec<f64>, String> {
    let system = system(lower_only);
    let mut solver = LinearSolver::new(&system, true).unwrap();
    let v = values(&system, entries);
    let mut rhs = vec![1.0; system.free_count];
    solver
        .factorize_and_solve(system.matrix(&v), &mut rhs)
        .map(|()| rhs)
        .map_err(|e| e.0)
}

fn diagonal_except(skip: &[usize]) -> Vec<(usize, usize, f64)> {
    (0..6)
        .filter(|i| !skip.contains(i))
        .map(|i| (i, i, 2.0))
        .collect()
}

#[test]
fn regular_matrix_is_solved() {
    for lower_only in [false, true] {
        let x = solve(lower_only, &diagonal_except(&[])).unwrap();
        assert!(x.iter().all(|&v| v == 0.5), "{x:?}");
    }
}

#[test]
fn dof_without_stiffness_is_named_by_node_and_axis() {
    // Equations: 0 = node 1 x, 1 = node 2 x, 2 = node 2 y, 3 = node 2 z, 4 = node 3 x, 5 = node 3 y.
    for lower_only in [false, true] {
        let err = solve(lower_only, &diagonal_except(&[2, 3])).unwrap_err();
        assert!(err.contains("no stiffness at node 2 (y, z)"), "{err}");
    }
}

#[test]
fn zero_pivot_is_an_error_naming_nodes_not_a_nan_solution() {
    // Node 3's x and y are coupled by the singular block [[1, 1], [1, 1]].
    let mut entries = diagonal_except(&[4, 5]);
    entries.extend([(4, 4, 1.0), (5, 5, 1.0), (5, 4, 1.0), (4, 5, 1.0)]);
    let err = solve(false, &entries).unwrap_err();
    assert!(
        err.contains("zero pivot") && err.contains("node 3"),
        "{err}"
    );
}

#[test]
fn symmetric_values_take_the_ldlt_and_others_the_lu() {
    let system = system(false);
    let mut solver = LinearSolver::new(&system, true).unwrap();
    let mut entries = diagonal_except(&[]);
    entries.extend([(4, 5, 0.5), (5, 4, 0.5)]);
    let mut rhs = vec![1.0; system.free_count];
    let v = values(&system, &entries);
    solver
        .factorize_and_solve(system.matrix(&v), &mut rhs)
        .unwrap();
    assert_eq!(solver.counts(), [0, 1, 0, 0]);
    assert!(
        (rhs[4] - 0.4).abs() < 1e-14 && (rhs[0] - 0.5).abs() < 1e-14,
        "{rhs:?}"
    );
    entries.push((4, 5, 0.25)); // unsymmetric now
    let v = values(&system, &entries);
    let mut rhs = vec![1.0; system.free_count];
    solver
        .factorize_and_solve(system.matrix(&v), &mut rhs)
        .unwrap();
    assert_eq!(
        solver.counts(),
        [0, 1, 0, 1],
        "GMRES on the unsymmetric one"
    );
}

/// Node 3's x and y coupled as `[[0, 1], [1, 0]]` (symmetric, indefinite, zero diagonal),
/// the identity elsewhere, and a right-hand side whose solution there is `(3, 1)`.
fn indefinite_pair(system: &System) -> (Vec<f64>, Vec<f64>) {
    let mut entries = diagonal_except(&[4, 5]);
    entries.extend([(4, 5, 1.0), (5, 4, 1.0)]);
    let mut rhs = vec![1.0; system.free_count];
    rhs[5] = 3.0;
    (values(system, &entries), rhs)
}

#[test]
fn symmetric_matrix_the_ldlt_cannot_pivot_is_solved_by_the_lu() {
    // Node 3's x and y: [[0, 1], [1, 0]] (symmetric, indefinite, zero diagonal).
    let system = system(false);
    let mut solver = LinearSolver::new(&system, true).unwrap();
    let (v, mut rhs) = indefinite_pair(&system);
    solver
        .factorize_and_solve(system.matrix(&v), &mut rhs)
        .unwrap();
    assert_eq!(solver.counts(), [1, 0, 1, 0]);
    assert_eq!((rhs[4], rhs[5]), (3.0, 1.0));
}

/// Fast paths that keep failing are skipped for `2^k − 1` solves after `k` failures in a row (at
/// most 31), every solution still right; one that succeeds is tried at the next solve again.
#[test]
fn failing_fast_paths_are_skipped_for_twice_as_many_solves_after_each_failure() {
    let system = system(false);
    let mut solver = LinearSolver::new(&system, true).unwrap();
    let (v, rhs) = indefinite_pair(&system);
    let mut attempts = Vec::new();
    for _ in 0..16 {
        let mut x = rhs.clone();
        let redone = solver.counts()[2];
        solver
            .factorize_and_solve(system.matrix(&v), &mut x)
            .unwrap();
        assert_eq!((x[4], x[5]), (3.0, 1.0));
        attempts.push(solver.counts()[2] - redone);
    }
    // Tried at solves 1, 3 (after 1 skipped), 7 (after 3), 15 (after 7).
    let tried: Vec<usize> = (0..16)
        .filter(|&i| attempts[i] == 1)
        .map(|i| i + 1)
        .collect();
    assert_eq!(tried, [1, 3, 7, 15]);
    assert_eq!(solver.counts()[0], 16, "every solve by the LU");
    // After a success the next solve tries them again.
    let mut b = FastBackoff::default();
    b.note(false, 0);
    assert!(!b.tries(true) && b.tries(true));
    b.note(true, 0);
    assert!(b.tries(true));
    (0..10).for_each(|_| b.note(false, 0));
    assert_eq!(b.skip, 31, "at most 31 skipped");
    assert!(
        b.tries(false),
        "always tried where the LU is not affordable"
    );
}

/// A GMRES solution that took more iterations than an LU costs counts as a failure of the fast
/// paths (the next solve goes to the LU); one within that count, or off GMRES's path, clears it.
#[test]
fn a_gmres_solution_dearer_than_the_lu_counts_as_a_failure_of_the_fast_paths() {
    let mut b = FastBackoff::default();
    b.note(true, GMRES_AS_DEAR_AS_LU + 1);
    assert!(!b.tries(true), "the next solve skips the fast paths");
    assert!(b.tries(true));
    b.note(true, GMRES_AS_DEAR_AS_LU);
    assert!(
        b.tries(true),
        "a solution within the count clears the record"
    );
    b.note(false, 0);
    b.note(true, 0);
    assert!(b.tries(true), "a direct or Woodbury solution clears it too");
}

/// A diagonally dominant symmetric matrix on the six equations plus `skew` (row, column,
/// value) added as `+v` at (row, column) and `−v` at (column, row).
fn unsymmetric(skew: &[(usize, usize, f64)]) -> Vec<(usize, usize, f64)> {
    let mut entries: Vec<(usize, usize, f64)> = (0..6).map(|i| (i, i, 4.0 + i as f64)).collect();
    for (i, j) in [(1, 0), (2, 1), (3, 2), (4, 3), (5, 4), (5, 3)] {
        entries.extend([(i, j, 0.7), (j, i, 0.7)]);
    }
    for &(i, j, v) in skew {
        entries.extend([(i, j, v), (j, i, -v)]);
    }
    entries
}

/// Solves `entries` with `method` (or by LU when `None`); the solution and the solver.
fn solve_with(
    entries: &[(usize, usize, f64)],
    method: Option<UnsymmetricMethod>,
) -> (Vec<f64>, LinearSolver) {
    let system = system(false);
    let mut solver = LinearSolver::new(&system, true).unwrap();
    match method {
        Some(m) => solver.set_method(m),
        None => solver.set_fast(false),
    }
    let v = values(&system, entries);
    let mut rhs: Vec<f64> = (0..system.free_count).map(|i| 1.0 + i as f64).collect();
    solver
        .factorize_and_solve(system.matrix(&v), &mut rhs)
        .unwrap();
    (rhs, solver)
}

#[test]
fn woodbury_and_gmres_solve_an_unsymmetric_matrix_like_lu_to_1e_10() {
    // Skew entries on equations 1, 2 and 4 (as a slipping gap's μ k_n coupling would).
    let entries = unsymmetric(&[(2, 1, 1.5), (4, 1, -0.9), (4, 2, 0.4)]);
    let (lu, _) = solve_with(&entries, None);
    let scale = lu.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    for method in [UnsymmetricMethod::Woodbury, UnsymmetricMethod::Gmres] {
        let (x, solver) = solve_with(&entries, Some(method));
        let p = solver.profile();
        let used = if method == UnsymmetricMethod::Woodbury {
            (p.woodbury_count, p.woodbury_columns, p.gmres_count)
        } else {
            (p.gmres_count, 0, p.woodbury_count)
        };
        assert_eq!(
            used,
            (
                1,
                if method == UnsymmetricMethod::Woodbury {
                    4
                } else {
                    0
                },
                0
            ),
            "{method:?}: {p:?}"
        );
        assert_eq!(solver.counts(), [0, 0, 0, 1], "{method:?}");
        assert!(!solver.has_lu(), "{method:?}: the LU is never analysed");
        let difference = max_difference(&x, &lu);
        assert!(difference <= 1e-10 * scale, "{method:?}: {difference:e}");
    }
    // Auto takes Woodbury for three skew DOFs.
    let (_, solver) = solve_with(&entries, Some(UnsymmetricMethod::Auto));
    assert_eq!(solver.profile().woodbury_count, 1);
}

#[test]
fn lu_is_analysed_only_when_a_fast_solution_fails_the_accuracy_check() {
    let system = system(false);
    let mut solver = LinearSolver::new(&system, true).unwrap();
    let mut rhs = vec![1.0; system.free_count];
    let v = values(&system, &unsymmetric(&[]));
    solver
        .factorize_and_solve(system.matrix(&v), &mut rhs)
        .unwrap();
    assert!(!solver.has_lu() && solver.counts() == [0, 1, 0, 0]);
    // Node 3's x and y: [[0, 1], [1, 0]] — the unpivoted LDLᵀ fails, the LU is built.
    let (v, mut rhs) = indefinite_pair(&system);
    solver
        .factorize_and_solve(system.matrix(&v), &mut rhs)
        .unwrap();
    assert!(solver.has_lu());
    assert_eq!(solver.counts(), [1, 1, 1, 0]);
    assert_eq!((rhs[4], rhs[5]), (3.0, 1.0));
    // Its analysis is kept and shared by a clone.
    assert!(solver.clone().has_lu());
}

#[test]
fn rounding_sized_asymmetry_counts_as_symmetric() {
    let mut entries = unsymmetric(&[]);
    entries.push((2, 1, 1e-15)); // below 1e-12 of the largest entry (9)
    let (_, solver) = solve_with(&entries, Some(UnsymmetricMethod::Auto));
    assert_eq!(solver.counts(), [0, 1, 0, 0]);
    entries.push((2, 1, 1e-10)); // above
    let (_, solver) = solve_with(&entries, Some(UnsymmetricMethod::Auto));
    assert_eq!(solver.counts(), [0, 0, 0, 1]);
}

fn max_difference(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

#[test]
fn non_finite_entry_is_named() {
    let mut entries = diagonal_except(&[]);
    entries.push((0, 0, f64::NAN));
    let err = solve(false, &entries).unwrap_err();
    assert!(err.contains("non-finite entries at node 1 (x)"), "{err}");
}

/// A name, whether the pattern is the lower triangle, the entries and the method (`None`: LU).
type Case<'a> = (
    &'a str,
    bool,
    &'a [(usize, usize, f64)],
    Option<UnsymmetricMethod>,
);

/// `solve_held` solves a second right-hand side with the factor of the last factorization on
/// every path (the Ju–Rowlands LDLᵀ, the symmetric part's LDLᵀ directly, by Woodbury and by
/// GMRES, the LU): no new factorization, the same factor identity, and the answer of a new
/// factorization to 1e-12. A new factorization gets a new identity.
/// Between profiles `p` and `q`: one held solve, no factorization, and the path `name` again
/// (one more column for Woodbury, its block kept; one GMRES solve for GMRES).
fn assert_one_held_solve_on_the_path(name: &str, p: &SolveProfile, q: &SolveProfile) {
    assert_eq!(
        (q.ldlt_count, q.lu_count, q.held_solves),
        (p.ldlt_count, p.lu_count, 1),
        "{name}"
    );
    let path = (
        q.woodbury_columns - p.woodbury_columns,
        q.gmres_count - p.gmres_count,
    );
    let expected = match name {
        "Woodbury" => (1, 0),
        "GMRES" => (0, 1),
        _ => (0, 0),
    };
    assert_eq!(path, expected, "{name}");
}

#[test]
fn a_held_factor_solves_another_right_hand_side_on_every_path() {
    let skew = unsymmetric(&[(2, 1, 1.5), (4, 1, -0.9), (4, 2, 0.4)]);
    let symmetric = unsymmetric(&[]);
    let lower: Vec<_> = symmetric.iter().copied().filter(|e| e.0 >= e.1).collect();
    let cases: [Case<'_>; 5] = [
        (
            "Ju–Rowlands LDLt",
            true,
            &lower,
            Some(UnsymmetricMethod::Auto),
        ),
        ("direct", false, &symmetric, Some(UnsymmetricMethod::Auto)),
        ("Woodbury", false, &skew, Some(UnsymmetricMethod::Woodbury)),
        ("GMRES", false, &skew, Some(UnsymmetricMethod::Gmres)),
        ("LU", false, &skew, None),
    ];
    for (name, lower_only, entries, method) in cases {
        let system = system(lower_only);
        let new_solver = || {
            let mut s = LinearSolver::new(&system, true).unwrap();
            match method {
                Some(m) => s.set_method(m),
                None => s.set_fast(false),
            }
            s
        };
        let v = values(&system, entries);
        let mut solver = new_solver();
        assert_eq!(solver.factor_id(), 0);
        let mut first = vec![1.0; system.free_count];
        solver
            .factorize_and_solve(system.matrix(&v), &mut first)
            .unwrap();
        let (id, p) = (solver.factor_id(), solver.profile());
        assert_ne!(id, 0, "{name}");
        let second: Vec<f64> = (0..system.free_count)
            .map(|i| 1.0 - 0.3 * i as f64)
            .collect();
        let mut held = second.clone();
        solver.solve_held(system.matrix(&v), &mut held).unwrap();
        assert_eq!(solver.factor_id(), id, "{name}");
        assert_one_held_solve_on_the_path(name, &p, &solver.profile());
        let mut fresh = second;
        new_solver()
            .factorize_and_solve(system.matrix(&v), &mut fresh)
            .unwrap();
        let scale = fresh.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
        assert!(
            max_difference(&held, &fresh) <= 1e-12 * scale,
            "{name}: {held:?} vs {fresh:?}"
        );
        solver
            .factorize_and_solve(system.matrix(&v), &mut first)
            .unwrap();
        assert!(solver.factor_id() > id, "{name}");
    }
}

/// The side-by-side sheet (1 m square, `n × n` nodes, edges pinned, prestress 1 MPa, centre
/// bulged 50 mm): its system and the consistent tangent's values there (or the Ju–Rowlands
/// lower triangle with `lower_only`).
fn sheet(n: usize, lower_only: bool) -> (System, Vec<f64>) {
    let h = 1.0 / (n - 1) as f64;
    let id = |i: usize, j: usize| j * n + i;
    let nodes: Vec<String> = (0..n * n)
        .map(|v| format!("[{},{},0]", (v % n) as f64 * h, (v / n) as f64 * h))
        .collect();
    let mut triangles = vec![];
    for j in 0..n - 1 {
        for i in 0..n - 1 {
            triangles.push(format!(
                "[{},{},{}]",
                id(i, j),
                id(i + 1, j),
                id(i + 1, j + 1)
            ));
            triangles.push(format!(
                "[{},{},{}]",
                id(i, j),
                id(i + 1, j + 1),
                id(i, j + 1)
            ));
        }
    }
    let supports: Vec<String> = (0..n * n)
        .filter(|&v| v % n == 0 || v / n == 0 || v % n == n - 1 || v / n == n - 1)
        .map(|v| format!(r#"{{"node":{v},"fixed":["x","y","z"]}}"#))
        .collect();
    let model = Model::from_json(&format!(
        r#"{{"name":"Sheet","nodes":[{}],"triangles":[{}],
             "material":{{"youngs_modulus":1e9,"poisson_ratio":0.3,"thickness":1e-3,
                          "prestress":[1e6,1e6,0]}},"supports":[{}]}}"#,
        nodes.join(","),
        triangles.join(","),
        supports.join(",")
    ))
    .unwrap();
    let system = System::new(&model, lower_only).unwrap();
    let mut u = vec![0.0; model.dof_count()];
    for (v, p) in model.nodes.iter().enumerate() {
        let s = (std::f64::consts::PI * p[0]).sin() * (std::f64::consts::PI * p[1]).sin();
        u[3 * v + 2] = 0.05 * s;
    }
    let mut values = vec![0.0; system.nonzeros()];
    let mut internal = vec![0.0; model.dof_count()];
    system.assemble(&u, &mut internal, Some(&mut values), |_, _| {
        unreachable!("no gaps")
    });
    (system, values)
}

/// The solution of the sheet's system for a right-hand side of ones, under `ordering` on
/// `threads` threads, and the factor's length.
fn sheet_solution(
    (system, values): &(System, Vec<f64>),
    ordering: FillOrdering,
    threads: usize,
) -> (Vec<f64>, usize) {
    let mut solver = LinearSolver::with_ordering(system, true, ordering).unwrap();
    solver.set_threads(threads);
    assert_eq!(solver.threads(), threads);
    let mut rhs: Vec<f64> = (0..system.free_count)
        .map(|i| 1.0 + (i % 7) as f64)
        .collect();
    solver
        .factorize_and_solve(system.matrix(values), &mut rhs)
        .unwrap();
    (rhs, solver.factor_len())
}

#[test]
fn factorization_on_two_and_three_threads_gives_the_same_bits_as_on_one() {
    // 29 k DOF under nested dissection: supernodes large enough for faer's parallel kernels.
    for lower_only in [false, true] {
        let sheet = sheet(101, lower_only);
        let (one, _) = sheet_solution(&sheet, FillOrdering::NestedDissection, 1);
        for threads in [2, 3] {
            let (many, _) = sheet_solution(&sheet, FillOrdering::NestedDissection, threads);
            let differ = one
                .iter()
                .zip(&many)
                .filter(|(a, b)| a.to_bits() != b.to_bits())
                .count();
            assert_eq!(
                differ, 0,
                "{threads} threads, lower only {lower_only}: {differ} values differ"
            );
        }
    }
}

#[test]
fn nested_dissection_solves_the_sheet_like_amd_to_1e_10() {
    let sheet = sheet(61, false);
    let (amd, _) = sheet_solution(&sheet, FillOrdering::Amd, 1);
    let (nd, _) = sheet_solution(&sheet, FillOrdering::NestedDissection, 1);
    let scale = amd.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    assert!(max_difference(&amd, &nd) <= 1e-10 * scale);
}

#[test]
fn nested_dissection_fills_the_200k_dof_sheet_within_15_percent_of_amd() {
    // The symbolic analyses alone (198 146 DOF). AMD gave 26.4 M values here and 30.6 M with
    // the centre node's z prescribed (its fill moves by 15 % with one node); ND 28.6 M there.
    let (system, _) = sheet(259, false);
    let len = |ordering| {
        LinearSolver::with_ordering(&system, true, ordering)
            .unwrap()
            .factor_len()
    };
    let (amd, nd) = (len(FillOrdering::Amd), len(FillOrdering::NestedDissection));
    assert!(nd as f64 <= 1.15 * amd as f64, "ND {nd} against AMD {amd}");
    assert_eq!(len(FillOrdering::Auto), nd, "the default at 200 k DOF");
}

#[test]
fn nested_dissection_orders_every_equation_once_across_components() {
    // Two 30 × 30 grids of 3-DOF nodes, not connected, and an isolated equation.
    let m = 30;
    let n = 2 * 3 * m * m + 1;
    let mut columns: Vec<Vec<usize>> = vec![vec![]; n];
    for offset in [0, 3 * m * m] {
        let node = |i: usize, j: usize| offset + 3 * (j * m + i);
        for j in 0..m {
            for i in 0..m {
                let mut near = vec![node(i, j)];
                if i + 1 < m {
                    near.push(node(i + 1, j));
                }
                if j + 1 < m {
                    near.push(node(i, j + 1));
                }
                for &a in &near {
                    for &b in &near {
                        for (da, db) in (0..3).flat_map(|x| (0..3).map(move |y| (x, y))) {
                            if b + db >= a + da {
                                columns[a + da].push(b + db);
                            }
                        }
                    }
                }
            }
        }
    }
    columns[n - 1].push(n - 1);
    let mut col_ptr = vec![0];
    let mut rows = vec![];
    for c in &mut columns {
        c.sort_unstable();
        c.dedup();
        rows.extend_from_slice(c);
        col_ptr.push(rows.len());
    }
    let pattern = faer::sparse::SymbolicSparseColMatRef::new_checked(n, n, &col_ptr, None, &rows);
    let (order, inverse) = ordering::nested_dissection(pattern);
    let mut seen = vec![false; n];
    for (k, &v) in order.iter().enumerate() {
        assert!(!seen[v], "equation {v} ordered twice");
        seen[v] = true;
        assert_eq!(inverse[v], k);
    }
    assert!(seen.iter().all(|&s| s), "an equation is missing");
}

#[test]
fn automatic_threads_stay_one_on_small_factors_and_explicit_counts_are_kept() {
    let mut solver = LinearSolver::new(&system(false), true).unwrap();
    solver.set_threads(0);
    assert_eq!(solver.threads(), 1);
    solver.set_threads(3);
    assert_eq!(solver.threads(), 3);
    let x = {
        let s = system(false);
        let v = values(&s, &diagonal_except(&[]));
        let mut rhs = vec![1.0; s.free_count];
        solver.factorize_and_solve(s.matrix(&v), &mut rhs).unwrap();
        rhs
    };
    assert!(x.iter().all(|&v| v == 0.5), "{x:?}");
}

#[test]
fn nested_dissection_splits_many_separate_equations_in_one_sweep() {
    // 200 000 uncoupled equations (a diagonal): one component each. Peeling them one by one
    // (a pass over the rest for each) took minutes; one sweep takes milliseconds.
    let n = 200_000;
    let col_ptr: Vec<usize> = (0..=n).collect();
    let rows: Vec<usize> = (0..n).collect();
    let pattern = faer::sparse::SymbolicSparseColMatRef::new_checked(n, n, &col_ptr, None, &rows);
    let started = std::time::Instant::now();
    let (order, _) = ordering::nested_dissection(pattern);
    assert_eq!(order.len(), n);
    let took = started.elapsed();
    assert!(took.as_secs_f64() < 3.0, "{took:?}");
}

/// `Aᵀ x = b` by a dense LU of the matrix of `entries` on the six equations.
fn dense_transpose_solution(entries: &[(usize, usize, f64)], b: &[f64]) -> Vec<f64> {
    let mut a = nalgebra::DMatrix::<f64>::zeros(6, 6);
    for &(i, j, v) in entries {
        a[(i, j)] += v;
    }
    let x = a
        .transpose()
        .lu()
        .solve(&nalgebra::DVector::from_column_slice(b))
        .expect("regular");
    x.iter().copied().collect()
}

#[test]
fn a_held_factor_solves_the_transpose_on_every_path_like_a_dense_reference() {
    // The skew part large enough that Aᵀ's solution is far from A's (a wrong sign shows).
    let skew = unsymmetric(&[(2, 1, 2.5), (4, 1, -1.9), (4, 2, 1.4)]);
    let symmetric = unsymmetric(&[]);
    let cases: [Case<'_>; 4] = [
        ("direct", false, &symmetric, Some(UnsymmetricMethod::Auto)),
        ("Woodbury", false, &skew, Some(UnsymmetricMethod::Woodbury)),
        ("GMRES", false, &skew, Some(UnsymmetricMethod::Gmres)),
        ("LU", false, &skew, None),
    ];
    let b: Vec<f64> = (0..6).map(|i| 1.0 - 0.3 * i as f64).collect();
    for (name, lower_only, entries, method) in cases {
        let system = system(lower_only);
        let mut solver = LinearSolver::new(&system, true).unwrap();
        match method {
            Some(m) => solver.set_method(m),
            None => solver.set_fast(false),
        }
        let v = values(&system, entries);
        let mut first = vec![1.0; system.free_count];
        solver
            .factorize_and_solve(system.matrix(&v), &mut first)
            .unwrap();
        let (id, p) = (solver.factor_id(), solver.profile());
        let mut x = b.clone();
        solver
            .solve_held_transpose(system.matrix(&v), &mut x)
            .unwrap();
        assert_eq!(solver.factor_id(), id, "{name}: no new factor");
        assert_one_held_solve_on_the_path(name, &p, &solver.profile());
        let reference = dense_transpose_solution(entries, &b);
        let scale = reference.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
        let difference = max_difference(&x, &reference);
        assert!(difference <= 1e-12 * scale, "{name}: {difference:e}");
    }
}

#[test]
fn a_transpose_solve_without_a_held_factor_is_an_lu_of_the_matrix() {
    let entries = unsymmetric(&[(2, 1, 2.5), (4, 1, -1.9), (4, 2, 1.4)]);
    let system = system(false);
    let mut solver = LinearSolver::new(&system, true).unwrap();
    let v = values(&system, &entries);
    let b: Vec<f64> = (0..6).map(|i| 0.5 + 0.2 * i as f64).collect();
    let mut x = b.clone();
    solver
        .solve_held_transpose(system.matrix(&v), &mut x)
        .unwrap();
    assert_eq!(solver.profile().lu_count, 1);
    assert_ne!(solver.factor_id(), 0, "the LU is held");
    let reference = dense_transpose_solution(&entries, &b);
    let scale = reference.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
    assert!(max_difference(&x, &reference) <= 1e-12 * scale);
    // The LU held now solves the next transpose without a factorization.
    let mut again = b;
    solver
        .solve_held_transpose(system.matrix(&v), &mut again)
        .unwrap();
    assert_eq!(solver.profile().lu_count, 1);
    assert_eq!(again, x);
}

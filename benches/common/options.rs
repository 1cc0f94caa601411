//! Command-line options shared by the load-path benches (`robustness`, `heldout`).

/// `--family NAME` (repeatable), `--quick`, `--failures`, `--check`, `--threads N`, and the
/// bench's own flags.
pub struct PathOptions {
    /// Families to run (all of `known` when none is named).
    pub families: Vec<String>,
    /// Every few paths of each family only.
    pub quick: bool,
    /// Print every failed path.
    pub failures: bool,
    /// Exit with status 1 unless every path converges.
    pub check: bool,
    /// Paths run in parallel (default: the available cores).
    pub threads: usize,
}

impl PathOptions {
    /// Parses the process arguments; `known` are the family names, `extra(flag, rest)` takes a
    /// bench's own flag (reading its value from `rest`) and says whether it knew it.
    pub fn parse(
        known: &[&str],
        mut extra: impl FnMut(&str, &mut dyn Iterator<Item = String>) -> Result<bool, String>,
    ) -> Result<Self, String> {
        let mut o = Self {
            families: vec![],
            quick: false,
            failures: false,
            check: false,
            threads: std::thread::available_parallelism().map_or(1, |n| n.get()),
        };
        let mut args = std::env::args().skip(1);
        while let Some(a) = args.next() {
            match a.as_str() {
                "--bench" => {}
                "--quick" => o.quick = true,
                "--failures" => o.failures = true,
                "--check" => o.check = true,
                "--family" => {
                    let name = args.next().ok_or("--family needs a name")?;
                    if !known.contains(&name.as_str()) {
                        return Err(format!("--family: unknown '{name}' (one of {known:?})"));
                    }
                    o.families.push(name);
                }
                "--threads" => {
                    o.threads = args
                        .next()
                        .and_then(|v| v.parse().ok())
                        .filter(|&n| n > 0)
                        .ok_or("--threads needs a positive integer")?
                }
                other => {
                    if !extra(other, &mut args)? {
                        return Err(format!("unknown option {other}"));
                    }
                }
            }
        }
        if o.families.is_empty() {
            o.families = known.iter().map(|s| s.to_string()).collect();
        }
        Ok(o)
    }
}

/// Sums over the paths of a table: paths, converged, Newton iterations, increments, cut-backs,
/// seconds of path time.
pub type Totals = (usize, usize, usize, usize, usize, f64);

impl PathOptions {
    /// Prints the total row (`blank` empty columns between cut-backs and path time), the wall
    /// time and, when asked or when checking with failures, the `failed` paths (name, message);
    /// with `--check`, exits with status 1 unless every path converged.
    pub fn finish(&self, total: Totals, blank: usize, wall: f64, failed: &[(String, String)]) {
        println!(
            "| **total** | {} | {} | {:.1} | {:.2} | | {} |{} {:.1} | |",
            total.0,
            total.1,
            100.0 * total.1 as f64 / total.0.max(1) as f64,
            total.2 as f64 / total.3.max(1) as f64,
            total.4,
            " |".repeat(blank),
            total.5
        );
        self.conclude((total.0, total.1), wall, failed);
    }

    /// Prints the wall time and, when asked or when checking with failures, the `failed` paths
    /// (name, message); with `--check`, exits with status 1 unless every path converged (`total`:
    /// paths, converged).
    pub fn conclude(&self, total: (usize, usize), wall: f64, failed: &[(String, String)]) {
        println!("\nwall time {wall:.1} s");
        if self.failures || (self.check && !failed.is_empty()) {
            println!("\n### failed paths\n");
            for (name, message) in failed {
                println!("- {name}: {message}");
            }
        }
        if self.check {
            if total.0 == 0 || !failed.is_empty() {
                eprintln!(
                    "check failed: {} of {} load paths converge",
                    total.1, total.0
                );
                std::process::exit(1);
            }
            println!("\ncheck passed: all {} load paths converge", total.0);
        }
    }
}

/// `f` of every item of `items`, on `threads` worker threads taking the next item as they
/// finish one; the results in the order of `items`.
pub fn on_threads<T: Sync, R: Send>(
    items: &[T],
    threads: usize,
    f: impl Fn(&T) -> R + Sync,
) -> Vec<R> {
    let next = std::sync::atomic::AtomicUsize::new(0);
    let results = std::sync::Mutex::new((0..items.len()).map(|_| None).collect::<Vec<_>>());
    std::thread::scope(|s| {
        for _ in 0..threads.max(1) {
            s.spawn(|| {
                loop {
                    let i = next.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                    let Some(item) = items.get(i) else { break };
                    let r = f(item);
                    results.lock().unwrap()[i] = Some(r);
                }
            });
        }
    });
    results
        .into_inner()
        .unwrap()
        .into_iter()
        .map(|r| r.expect("every item ran"))
        .collect()
}

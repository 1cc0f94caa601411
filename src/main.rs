use membrane_contact::mech::{Analysis, ParallelArch, SolverSettings};
fn main() {
    for (h, f) in [(0.3, -1.0), (0.3, -1.5), (0.2,-1.5), (0.4,-1.5)] {
        let spec = ParallelArch { target_dz_per_height: f, ..ParallelArch::with_height(h) };
        let model = spec.model().unwrap();
        let mut a = Analysis::new(model, SolverSettings::default()).unwrap();
        let t = std::time::Instant::now();
        let rep = a.step_to(&[spec.target()], 20);
        println!("{h}: {:?} {:?}", rep, t.elapsed());
        let r = a.results();
        for g in &r.gaps { println!("  slip {:8.3} mm  N {:9.3}  T {:9.3} {:?}", g.slip_x*1e3, g.normal_force, g.friction_force, g.status); }
        println!("  vm range {:?} reactions {:?}", r.von_mises_range(), r.reactions);
    }
}

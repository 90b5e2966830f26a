use rod_ig_core::{planar, PlanarParams};
use std::time::Instant;
fn main() {
    for a in [[2.0, -10.0, 5.0], [0.05, 1e-8, 1e-8], [1e-30, 1e-30, 1e-30], [1.0, 1e-6, 1e-6], [-1e-5, 1873.0, -4.4e-4], [0.01, 1e4, 0.01], [1e-3, 1e5, 0.0], [0.0, 1e6, 1e-8], [0.0, -1e6, 1e-8], [1e-8, 3.0, 1e-8], [1e-8, -30.0, 1e-8]] {
        let p = PlanarParams::new(a[0], a[1], a[2]);
        for (name, f) in [("tip", 0), ("tip+J", 1), ("stab", 2), ("eval", 3)] {
            let t = Instant::now();
            let mut n = 0;
            let mut r = String::new();
            while t.elapsed().as_secs_f64() < 0.05 {
                r = match f { 0 => format!("{:?}", planar::tip(&p).map(|_| ())), 1 => format!("{:?}", planar::tip_and_jacobian(&p).map(|_| ())), 2 => format!("{:?}", planar::stability(&p).map(|s| (s.stable, s.uncertain))), _ => format!("{:?}", planar::evaluate(&p).map(|_| ())) };
                n += 1;
            }
            print!("{name} {:.1}µs {r:.60} | ", t.elapsed().as_secs_f64() * 1e6 / n as f64);
        }
        println!(" {a:?}");
    }
}

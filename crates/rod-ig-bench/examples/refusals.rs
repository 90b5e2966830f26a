use rod_ig_core::planar::{self, PlanarRod};
use rod_ig_core::PlanarParams;
fn main() {
    let text = std::fs::read_to_string("crates/rod-ig-core/tests/data/tension_truth.jsonl")
        .unwrap()
        + &std::fs::read_to_string("crates/rod-ig-core/tests/data/tension_near_straight.jsonl")
            .unwrap();
    for line in text.lines() {
        let i = line.find("\"a\"").unwrap();
        let rest = &line[i..];
        let s = rest.find('[').unwrap();
        let e = rest.find(']').unwrap();
        let v: Vec<f64> = rest[s + 1..e]
            .split(',')
            .map(|x| x.trim().parse().unwrap())
            .collect();
        let a = PlanarParams::new(v[0], v[1], v[2]);
        let shape = PlanarRod::new(&a).is_ok();
        let ev = planar::evaluate(&a);
        let tip = planar::tip(&a).is_ok();
        let tj = planar::tip_and_jacobian(&a);
        let st = planar::stability(&a);
        if shape != ev.is_ok() {
            println!(
                "{:?} shape {shape} tip {tip} tipJ {} stab {:?} eval {:?}",
                v,
                tj.is_ok(),
                st.as_ref().err(),
                ev.err().map(|e| e.to_string())
            );
        }
    }
}

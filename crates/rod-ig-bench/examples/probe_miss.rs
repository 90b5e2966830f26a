use rod_ig_core::planar::heavy::{self, cable::Cable, Gravity};
use rod_ig_core::PlanarParams;
fn main() {
    let g = Gravity::new(332.637563434832, [0.0, -1.0]).unwrap();
    let a = PlanarParams::new(2.940827470e0, 6.112670146e1, -2.015872761e2);
    let c = Cable::from_params(&a, &g).unwrap();
    let sv = c.second_variation().unwrap();
    println!("tip {:?} sv {:?} turns {:?}", c.tip(), sv, c.turns());
    for p in heavy::shape(&a, &g, 21).unwrap() {
        println!("{:.3} {:.3} {:.3}", p.x, p.y, p.theta);
    }
}

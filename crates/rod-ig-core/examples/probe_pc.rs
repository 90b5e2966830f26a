use nalgebra::UnitQuaternion;
use rod_ig_core::spatial::cable::SpatialCable;
use rod_ig_core::spatial::heavy::Gravity3;
use rod_ig_core::spatial::{SpatialParams, Stiffness};
fn main() {
    let k = Stiffness::default();
    let g = Gravity3::new(20.0, [0.0, 0.0, -1.0]).unwrap();
    let a = SpatialParams::new(0.0, 0.0, 0.0, -5.0, 3.0, 1.0);
    let c0 = SpatialCable::from_params(&a, &k, &g).unwrap();
    println!("identity clamped: {:?}", c0.stability().unwrap());
    let a2 = SpatialParams::new(1e-3, 0.0, 0.0, -5.0, 3.0, 1.0);
    let c2 = SpatialCable::from_params(&a2, &k, &g).unwrap();
    println!("identity clamped a_m small: {:?}", c2.stability().unwrap());
    let base = UnitQuaternion::from_euler_angles(0.3, -0.4, 0.2);
    let c1 = SpatialCable::pinned_from_params(&a, &k, &g, base).unwrap();
    println!("rotated: {:?}", c1.stability().unwrap());
    let g2 = Gravity3::new(
        20.0,
        (base.inverse() * nalgebra::Vector3::new(0.0, 0.0, -1.0)).into(),
    )
    .unwrap();
    let f = base.inverse() * nalgebra::Vector3::new(-5.0, 3.0, 1.0);
    let a3 = SpatialParams::new(0.0, 0.0, 0.0, f.x, f.y, f.z);
    let c3 = SpatialCable::from_params(&a3, &k, &g2).unwrap();
    println!("same rod in base frame: {:?}", c3.stability().unwrap());
}

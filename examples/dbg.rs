use nalgebra::Point3;
use talus::geometry::{generators, gjk::*, Pose};
fn main() {
    let cube = generators::cuboid(1.0, 1.0, 1.0).unwrap();
    let r = gjk(&cube, &PointShape(Point3::origin()), &Pose::translation(0.1, 0.2, 0.7), None);
    println!("{r:?}");
}

//! Particle poses in CSV: `x,y,z,qw,qx,qy,qz` and optionally `vx,vy,vz,wx,wy,wz`
//! (header line first; columns found by name, so their order is free).

use std::path::Path;

use nalgebra::{Point3, UnitQuaternion, Vector3};

use super::csv_table::CsvTable;
use crate::Real;

/// One particle's pose and velocities.
#[derive(Clone, Debug, PartialEq)]
pub struct PoseRecord {
    /// Centroid.
    pub position: Point3<Real>,
    /// Orientation of the body frame.
    pub orientation: UnitQuaternion<Real>,
    /// Velocity.
    pub velocity: Vector3<Real>,
    /// Angular velocity.
    pub angular_velocity: Vector3<Real>,
}

/// Reads a pose file; errors name the file, the line and the column.
pub fn read_poses(path: &Path) -> Result<Vec<PoseRecord>, String> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| format!("{}: cannot read: {e}", path.display()))?;
    parse_poses(&text).map_err(|e| format!("{}:{e}", path.display()))
}

/// Parses pose CSV text (errors start with the line number).
pub fn parse_poses(text: &str) -> Result<Vec<PoseRecord>, String> {
    let table = CsvTable::parse(text, "x,y,z,qw,qx,qy,qz")?;
    let mut cols = [0usize; 7];
    for (c, name) in cols.iter_mut().zip(["x", "y", "z", "qw", "qx", "qy", "qz"]) {
        *c = table.require(name)?;
    }
    let optional = ["vx", "vy", "vz", "wx", "wy", "wz"].map(|n| table.column(n));
    let mut out = Vec::new();
    for record in table.records() {
        let mut v = [0.0; 13];
        for k in 0..7 {
            v[k] = record.value(cols[k])?;
        }
        for (k, c) in optional.iter().enumerate() {
            if let Some(c) = c {
                v[7 + k] = record.value(*c)?;
            }
        }
        let Some(orientation) = crate::geometry::unit_quaternion(v[3], v[4], v[5], v[6]) else {
            return Err(format!("{}: the quaternion is zero", record.line));
        };
        out.push(PoseRecord {
            position: Point3::new(v[0], v[1], v[2]),
            orientation,
            velocity: Vector3::new(v[7], v[8], v[9]),
            angular_velocity: Vector3::new(v[10], v[11], v[12]),
        });
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn columns_by_name_and_errors_by_line() {
        let poses = parse_poses("qw,qx,qy,qz,x,y,z,vz\n1,0,0,0,1,2,3,-4\n").unwrap();
        assert_eq!(poses[0].position, Point3::new(1.0, 2.0, 3.0));
        assert_eq!(poses[0].velocity.z, -4.0);
        let e = parse_poses("x,y,z,qw,qx,qy,qz\n0,0,0,1,0,0,0\n0,0,zero,1,0,0,0\n").unwrap_err();
        assert!(e.starts_with("3:") && e.contains("'z'"), "{e}");
        assert!(parse_poses("x,y,z\n").unwrap_err().contains("qw"));
    }
}

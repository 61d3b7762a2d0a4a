//! Rotations from numbers as a user or a master writes them.

use nalgebra::{Quaternion, UnitQuaternion};

use crate::Real;

/// The rotation of the quaternion `(w, x, y, z)`, normalised; `None` when it is zero
/// or not finite. The components are divided by the largest first, so that a
/// quaternion such as `(0.5, 0.5, 5e307, 0.5)` normalises instead of overflowing its
/// norm to infinity (which leaves the zero quaternion, and NaN rotations after it).
pub fn unit_quaternion(w: Real, x: Real, y: Real, z: Real) -> Option<UnitQuaternion<Real>> {
    let largest = [w, x, y, z].iter().fold(0.0, |m: Real, c| m.max(c.abs()));
    if !(largest.is_finite() && largest > 0.0) || [w, x, y, z].iter().any(|c| c.is_nan()) {
        return None;
    }
    let q = Quaternion::new(w / largest, x / largest, y / largest, z / largest);
    Some(UnitQuaternion::from_quaternion(q))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn huge_tiny_zero_and_non_finite_quaternions() {
        let q = unit_quaternion(0.5, 0.5, 5e307, 0.5).unwrap();
        assert!((q.quaternion().norm() - 1.0).abs() < 1e-15);
        assert!((q.j - 1.0).abs() < 1e-15);
        let q = unit_quaternion(1e-310, 0.0, 0.0, 0.0).unwrap();
        assert_eq!(q.w, 1.0);
        let half = unit_quaternion(2.0, 2.0, 2.0, 2.0).unwrap();
        assert!((half.w - 0.5).abs() < 1e-15);
        assert!(unit_quaternion(0.0, 0.0, 0.0, 0.0).is_none());
        assert!(unit_quaternion(1.0, Real::NAN, 0.0, 0.0).is_none());
        assert!(unit_quaternion(1.0, Real::INFINITY, 0.0, 0.0).is_none());
    }
}

//! The free surface of a bed in a drum's cross-section, fitted as a straight line.
//!
//! **Method.** The particle centres of the central slice, as points `(h, v)` across
//! the drum (`h` horizontal, `v` up), are put in columns 1.5 particle diameters `d`
//! wide (wider than the spacing of neighbours along any surface row, so each column
//! holds a particle of the top row). In each column the surface point is the highest
//! centre with two more centres of the column at most `2d` below it (a packed column
//! holds about three): particles further above the rest, alone or in pairs, are in
//! flight (cataracting) and not part of the surface. Columns with fewer than three
//! particles are skipped. A least-squares line is fitted to the surface points of
//! the middle 60 % of the surface's horizontal extent, which leaves out the shoulder
//! that the rising wall lifts and the toe at the falling wall. The dynamic angle of repose is the
//! line's inclination, `atan |slope|`.

use crate::Real;

/// A straight free surface `v = intercept + slope · h` in the cross-section.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfaceFit {
    /// dv/dh.
    pub slope: Real,
    /// Height of the surface at h = 0 (the drum's axis), m.
    pub intercept: Real,
    /// Surface points the line was fitted to.
    pub points: usize,
}

impl SurfaceFit {
    /// Inclination to the horizontal, degrees (0 to 90).
    pub fn angle_degrees(&self) -> Real {
        self.slope.atan().abs().to_degrees()
    }

    /// Signed height of point `(h, v)` above the line, measured along the line's
    /// normal.
    pub fn height_above(&self, h: Real, v: Real) -> Real {
        (v - self.intercept - self.slope * h) / (1.0 + self.slope * self.slope).sqrt()
    }
}

/// Fits the free surface to particle centres `points` (`[h, v]`), `diameter` being
/// the particles' circumscribed diameter. `None` when fewer than three columns have
/// a surface point.
pub fn fit_surface(points: &[[Real; 2]], diameter: Real) -> Option<SurfaceFit> {
    if !(diameter > 0.0) || points.is_empty() {
        return None;
    }
    let mut columns: std::collections::BTreeMap<i64, Vec<[Real; 2]>> = Default::default();
    for p in points {
        if p.iter().all(|x| x.is_finite()) {
            columns
                .entry((p[0] / (1.5 * diameter)).floor() as i64)
                .or_default()
                .push(*p);
        }
    }
    let mut surface = Vec::new();
    for column in columns.values_mut() {
        column.sort_by(|a, b| b[1].total_cmp(&a[1]));
        if let Some(k) = (0..column.len().saturating_sub(2))
            .find(|&k| column[k][1] - column[k + 2][1] <= 2.0 * diameter)
        {
            surface.push(column[k]);
        }
    }
    let (lo, hi) = surface
        .iter()
        .fold((Real::INFINITY, Real::NEG_INFINITY), |(lo, hi), p| {
            (lo.min(p[0]), hi.max(p[0]))
        });
    let margin = 0.2 * (hi - lo);
    let middle: Vec<[Real; 2]> = surface
        .into_iter()
        .filter(|p| p[0] >= lo + margin && p[0] <= hi - margin)
        .collect();
    if middle.len() < 3 {
        return None;
    }
    let n = middle.len() as Real;
    let mh = middle.iter().map(|p| p[0]).sum::<Real>() / n;
    let mv = middle.iter().map(|p| p[1]).sum::<Real>() / n;
    let shh: Real = middle.iter().map(|p| (p[0] - mh).powi(2)).sum();
    let shv: Real = middle.iter().map(|p| (p[0] - mh) * (p[1] - mv)).sum();
    if !(shh > 0.0) {
        return None;
    }
    let slope = shv / shh;
    Some(SurfaceFit {
        slope,
        intercept: mv - slope * mh,
        points: middle.len(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A packed bed in a drum of radius `radius` under a surface through the axis
    /// inclined at `angle`: a hexagonal packing of spacing `d` whose rows run along
    /// the surface, as shear in a flowing layer orders them.
    fn inclined_bed(angle_deg: Real, d: Real, radius: Real) -> Vec<[Real; 2]> {
        let (sin, cos) = angle_deg.to_radians().sin_cos();
        let mut pts = Vec::new();
        let n = (2.0 * radius / d) as i64;
        for j in 0..=n {
            for i in -n..=n {
                let s = (i as Real + 0.5 * (j & 1) as Real) * d;
                let depth = j as Real * d * 0.75f64.sqrt();
                let p = [s * cos + depth * sin, s * sin - depth * cos];
                if p[0].hypot(p[1]) < radius - 0.5 * d {
                    pts.push(p);
                }
            }
        }
        pts
    }

    #[test]
    fn the_angle_of_an_inclined_packed_bed_is_recovered() {
        for angle in [0.0, 15.0, 30.0, 40.0] {
            let bed = inclined_bed(angle, 0.01, 0.15);
            let fit = fit_surface(&bed, 0.01).expect("a surface");
            // Each column's surface point lies on the top row, up to where in the
            // column it falls: the fit is exact but for round-off.
            assert!(
                (fit.angle_degrees() - angle).abs() < 1e-9,
                "{angle}: fitted {}",
                fit.angle_degrees()
            );
        }
    }

    #[test]
    fn particles_in_flight_are_not_the_surface() {
        let mut bed = inclined_bed(30.0, 0.01, 0.15);
        let clean = fit_surface(&bed, 0.01).unwrap();
        // A shower of particles 5 cm above the surface over the middle.
        for k in 0..10 {
            let h = -0.05 + 0.01 * k as Real;
            bed.push([h + 0.003, 30f64.to_radians().tan() * h + 0.05]);
        }
        let fit = fit_surface(&bed, 0.01).unwrap();
        assert_eq!(fit, clean);
    }

    #[test]
    fn too_few_columns_give_no_surface() {
        assert!(fit_surface(&[[0.0, 0.0], [0.0, 0.01]], 0.01).is_none());
        assert!(fit_surface(&[], 0.01).is_none());
    }
}

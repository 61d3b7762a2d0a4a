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
//! the middle 60 % of the surface's extent, which leaves out the shoulder that the
//! rising wall lifts and the toe at the falling wall. The fit is repeated twice with
//! the columns turned normal to the line found, so that on a steep surface they do
//! not cut the flowing layer obliquely. The dynamic angle of repose is the line's
//! inclination, `atan |slope|`.

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
    /// Inclination to the horizontal, rad (0 to π/2).
    pub fn angle(&self) -> Real {
        self.slope.atan().abs()
    }

    /// Inclination to the horizontal, degrees (0 to 90).
    pub fn angle_degrees(&self) -> Real {
        self.angle().to_degrees()
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
///
/// The columns are first vertical, then turned to stand normal to the line found,
/// twice: on a steep surface vertical columns cut the flowing layer obliquely and
/// their gap criterion reaches into it, while normal to the surface a column sees
/// the layer's particles stacked as in a flat bed.
pub fn fit_surface(points: &[[Real; 2]], diameter: Real) -> Option<SurfaceFit> {
    let mut fit = fit_in_columns(points, diameter)?;
    for _ in 0..2 {
        let angle = fit.slope.atan();
        let (sin, cos) = angle.sin_cos();
        let turned: Vec<[Real; 2]> = points
            .iter()
            .map(|p| [p[0] * cos + p[1] * sin, -p[0] * sin + p[1] * cos])
            .collect();
        let Some(local) = fit_in_columns(&turned, diameter) else {
            break;
        };
        // The local line through (0, a) at slope b, back in the drum's frame.
        let foot = [-local.intercept * sin, local.intercept * cos];
        let slope = (angle + local.slope.atan()).tan();
        fit = SurfaceFit {
            slope,
            intercept: foot[1] - slope * foot[0],
            points: local.points,
        };
    }
    Some(fit)
}

/// The surface's points: in columns 1.5 `diameter`s wide along the v axis, each
/// column's highest centre with two more within two diameters below it (so that
/// particles in flight are not the surface), in the order of the columns.
pub fn surface_points(points: &[[Real; 2]], diameter: Real) -> Vec<[Real; 2]> {
    if !(diameter > 0.0) {
        return Vec::new();
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
    surface
}

/// One fit with columns along the v axis.
fn fit_in_columns(points: &[[Real; 2]], diameter: Real) -> Option<SurfaceFit> {
    let surface = surface_points(points, diameter);
    if surface.is_empty() {
        return None;
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
        for angle in [0.0, 15.0, 30.0, 40.0, 55.0, 70.0] {
            let bed = inclined_bed(angle, 0.01, 0.15);
            let fit = fit_surface(&bed, 0.01).expect("a surface");
            // Each column's surface point lies on the top row, up to where in the
            // column it falls: the fit is exact but for round-off.
            assert!(
                (fit.angle_degrees() - angle).abs() < 1e-6,
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
        assert!(
            (fit.slope - clean.slope).abs() < 1e-9
                && (fit.intercept - clean.intercept).abs() < 1e-9
        );
    }

    #[test]
    fn too_few_columns_give_no_surface() {
        assert!(fit_surface(&[[0.0, 0.0], [0.0, 0.01]], 0.01).is_none());
        assert!(fit_surface(&[], 0.01).is_none());
    }
}

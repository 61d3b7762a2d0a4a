//! Contact geometry and the motion of the bodies → the force and torque of one
//! contact, through the contact laws of [`crate::contact`].

use nalgebra::{Point3, Vector3};

use super::dispatch::ContactGeometry;
pub(super) use super::relative_motion::RelativeMotion;
use crate::Real;
use crate::contact::{
    DampingTable, NormalContact, PairStiffness, Regularisation, TangentialHistory, normal_force,
    rocking_damping, tangential_force, twisting_friction,
};
use crate::engine::laws::{ContactLaws, PairLaw};
use crate::world::World;

/// The force and torque one contact puts on its second body; the first body gets the
/// opposite force and the torque that balances angular momentum.
#[derive(Clone, Copy, Debug)]
pub(super) struct ContactForce {
    pub force: Vector3<Real>,
    /// Torque on body 2 about its centroid.
    pub torque: Vector3<Real>,
    pub history: TangentialHistory,
    /// Elastic energy held in the contact: the normal law's potential and the
    /// friction spring's.
    pub energy: Real,
    /// Energy the contact dissipated over the step ([`dissipated`]).
    pub dissipated: Real,
}

impl ContactForce {
    /// Torque on body 1 about `x1`, given body 2's centroid `x2`: what keeps the
    /// pair's angular momentum.
    #[inline]
    pub(super) fn reaction_torque(&self, x1: &Point3<Real>, x2: &Point3<Real>) -> Vector3<Real> {
        -(self.torque + (x2 - x1).cross(&self.force))
    }
}

/// What a pair adds to its particles: the force and the torque on each body and the
/// energy its contact holds and dissipated, all zero when the pair does not touch
/// (but for the energy of a friction spring let go as the pair parted).
///
/// The contact's history is written beside its pair instead, so that a result kept
/// for later (a pair that a part of the sweep defers) stays small. The torque on
/// body 1 is taken here, where the pair's positions are at hand.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct PairResult {
    /// Force on body 2; body 1 gets the opposite.
    pub force: Vector3<Real>,
    /// Torque on body 1 ([`ContactForce::reaction_torque`]) and on body 2, each about
    /// its centroid.
    pub torques: [Vector3<Real>; 2],
    pub energy: Real,
    pub dissipated: Real,
    /// Whether the bodies touch.
    pub touching: bool,
}

impl PairResult {
    /// The result of contact `c` between bodies at `x1` and `x2`.
    #[inline]
    pub(super) fn new(c: &ContactForce, x1: &Point3<Real>, x2: &Point3<Real>) -> Self {
        PairResult {
            force: c.force,
            torques: [c.reaction_torque(x1, x2), c.torque],
            energy: c.energy,
            dissipated: c.dissipated,
            touching: true,
        }
    }

    /// The result of a pair apart whose contact held `history` until now: the
    /// friction spring's energy is let go with it.
    #[inline]
    pub(super) fn parted(history: &TangentialHistory) -> Self {
        PairResult {
            dissipated: history.spring_energy(),
            ..Default::default()
        }
    }
}

/// Energy a contact dissipates over a step of `dt`: the work that its
/// `non_conservative` force on body 2 (the normal law's damping and friction, acting
/// at the contact point, where `motion` is measured) and pure `torque` on body 2 take
/// from the relative motion, less what its friction spring stored meanwhile (from
/// `before` to `after`).
///
/// The normal damping and sliding friction are taken at the step's end velocity;
/// `ahead` is their share of `non_conservative · total`, with `total` the contact's
/// whole force on body 2 ([`ahead`]). A force evaluated now acts through the closing
/// half kick of this step and the opening one of the next, and the kinetic energy
/// those two kicks change is exactly `dt F · v` at the velocity between them. The
/// contact's own `total` moves the `motion` measured (the half-step velocity) there
/// by half a kick, `dt/2 · total / m_eff`: exact along the normal for a contact alone
/// on its bodies, which an impact is. Where the bodies have other contacts, their
/// kicks are left out (a quasi-static bed's are balanced; predicting them from the
/// last step's forces misjudged the first step of every impact, whose damping stops
/// the approach within a few steps). At the half-step velocity alone, an impact
/// damped within a few steps is booked ~10 % too much dissipation at the suggested
/// step.
///
/// Sticking friction is a spring, taken at the half-step velocity it is stretched by
/// (`s += v_t dt`): its work and its energy change then cancel but for
/// `½ k Δs² ≥ 0`, and a contact held at rest books nothing. At the predicted end
/// velocity, a sticking contact whose bodies other contacts hold (a bed at rest)
/// booked `−dt²/2 · |F_t|² / m_eff` every step, energy made from nothing: a bed of
/// 5000 Hertz spheres held still for 0.2 s booked −1.05e-2 J, an error of
/// −1.1e-2 J (now +8.8e-4 J and +2.3e-5 J). The price is in a pour, where sticking
/// contacts of impacts do move with their own kick: its error at the suggested step
/// rose from 2.4e-4 to 1.2e-3 of the dissipation for polyhedra and from 1.4e-2 to
/// 1.9e-2 for Hertz spheres, still first order in the step (`tests/energy_ledger.rs`).
///
/// What is left conservative is the normal law's elastic force and torque, whose
/// work is the change of its potential: the energy a run loses beyond this
/// dissipation and the walls' work is the integration's error (see
/// `scene::energy_ledger`). The twisting and rolling springs' energies are counted
/// as dissipated while they hold them (they are a small share, and give it back as
/// negative dissipation).
#[inline]
pub(super) fn dissipated(
    (non_conservative, ahead): (&Vector3<Real>, Real),
    torque: &Vector3<Real>,
    motion: &RelativeMotion,
    (before, after): (&TangentialHistory, &TangentialHistory),
    dt: Real,
) -> Real {
    let kick = 0.5 * dt * motion.inverse_mass;
    -dt * (non_conservative.dot(&motion.velocity) + kick * ahead + torque.dot(&motion.spin))
        - (after.spring_energy() - before.spring_energy())
}

/// The share of a contact's non-conservative force dotted with its whole force
/// that [`dissipated`] takes at the step's end velocity: the normal damping's,
/// `(N − E) N` for a normal force `N` of elastic part `E`, and friction's
/// `|F_t|²` (the friction is tangent, the normal force normal) where it slides.
#[inline]
pub(super) fn ahead(normal: Real, elastic: Real, friction: &Vector3<Real>, sliding: bool) -> Real {
    let damping = (normal - elastic) * normal;
    if sliding {
        damping + friction.norm_squared()
    } else {
        damping
    }
}

/// The contact law's inputs that do not depend on the pair.
#[derive(Clone, Copy, Debug)]
pub(super) struct LawInputs<'a> {
    pub stiffness: PairStiffness,
    pub damping: &'a DampingTable,
    pub friction: Real,
    /// Regularisation volume `V₀` of the normal law.
    pub regularisation: Regularisation,
    pub dt: Real,
}

impl<'a> LawInputs<'a> {
    /// The inputs of a contact under `law`, one of `laws`'.
    #[inline]
    pub(super) fn new(laws: &'a ContactLaws, law: &PairLaw, dt: Real) -> Self {
        LawInputs {
            stiffness: law.stiffness,
            damping: laws.damping(law),
            friction: law.friction,
            regularisation: law.regularisation,
            dt,
        }
    }
}

/// Normal and tangential force on body 2 of a contact whose centroid is `centre`.
#[inline]
pub(super) fn contact_force(
    g: &ContactGeometry,
    motion: &RelativeMotion,
    law: &LawInputs,
    history: TangentialHistory,
    centre: &Point3<Real>,
) -> ContactForce {
    let (damping, dt) = (law.damping, law.dt);
    let relative_velocity = motion.velocity;
    let effective_mass = 1.0 / motion.inverse_mass;
    let normal = normal_force(
        &NormalContact {
            volume: g.volume,
            area: g.area,
            depth: g.depth,
            normal: g.normal,
            relative_velocity,
            effective_mass,
            stiffness: law.stiffness.normal,
            regularisation: law.regularisation,
            dt,
        },
        damping,
    );
    let kt = law.stiffness.tangential * g.area;
    let ct = 2.0 * damping.zeta(1.0) * (effective_mass * kt).sqrt();
    let t = tangential_force(
        &history,
        &g.normal,
        &relative_velocity,
        dt,
        kt,
        ct,
        law.friction * normal.force.norm(),
    );
    let force = normal.force + t.force;
    let rocking = if g.depth > 0.0 {
        rocking_damping(
            &motion.spin,
            &g.normal,
            g.area,
            normal.exponent * normal.elastic / g.depth,
            motion.inertia,
            damping.zeta(1.0),
            dt,
        )
    } else {
        Vector3::zeros()
    };
    let (twisting, twist) = twisting_friction(
        history.twist,
        &motion.spin,
        &g.normal,
        g.area,
        kt,
        motion.inertia,
        law.friction * normal.force.norm(),
        dt,
    );
    let torque = rocking
        + twisting
        + match g.rotation_gradient {
            // Elastic part from the potential (U' = elastic / area); damping and friction,
            // measured at the contact point, act there.
            Some(rotation) if g.area > 0.0 => {
                let elastic = g.normal * normal.elastic;
                -(normal.elastic / g.area) * rotation + (g.point - centre).cross(&(force - elastic))
            }
            _ => (g.point - centre).cross(&force),
        };
    let kept = TangentialHistory { twist, ..t.history };
    ContactForce {
        force,
        torque,
        history: kept,
        energy: normal.energy + kept.spring_energy(),
        dissipated: dissipated(
            (
                &(force - g.normal * normal.elastic),
                ahead(normal.magnitude, normal.elastic, &t.force, t.sliding),
            ),
            &(rocking + twisting),
            motion,
            (&history, &kept),
            dt,
        ),
    }
}

/// The force on particle `j` of its contact with particle `i` of geometry `g`.
#[inline]
pub(super) fn pair_force(
    world: &World,
    i: usize,
    j: usize,
    g: &ContactGeometry,
    history: TangentialHistory,
    laws: &ContactLaws,
    dt: Real,
) -> ContactForce {
    let p = &world.particles;
    let law = laws.pair(p.body_type[i], p.body_type[j]);
    let motion = RelativeMotion::of_pair(world, [i, j], &g.point, &g.normal, law.inertia);
    contact_force(
        g,
        &motion,
        &LawInputs::new(laws, &law, dt),
        history,
        &p.position[j],
    )
}

//! The CUDA backend's kernels (feature `cuda`; issue 23): CUDA C sources in
//! `kernels/`, compiled at run time through NVRTC ([`nvrtc`]) and, where no GPU is
//! at hand, compiled as C++ and run on the CPU by the [`host`] executor, which
//! launches them as the driver does (blocks of threads, the parameters as an array
//! of pointers), the blocks in parallel.
//!
//! A [`device::Device`] holds buffers and launches kernels: the CUDA driver
//! ([`driver::CudaDevice`]) or the host executor ([`device::HostDevice`]), behind
//! one interface, so the code that drives the kernels is the same on both.
//! [`stepper::DeviceWorld`] steps a world of spheres, convex polyhedra or both,
//! under every contact law of the CPU backend, with its walls, on a device:
//! integration, the candidate list (a hashed cell grid, pairs by prefix sum), the
//! pair contacts with their tangential history, the gather, the wall contacts
//! (the facets near a particle found through each wall's facet grid) and the
//! walls' sums. Through the host executor it gives the CPU backend's bits for
//! spheres and agrees to round-off for polyhedra; [`backend`] puts it behind the
//! backend seam, on one device per MPI rank.

pub mod backend;
pub mod device;
pub mod device_body_types;
mod device_facet_grids;
mod device_hertz;
mod device_list;
pub mod device_pair_contacts;
pub mod device_polyhedra;
pub mod device_states;
mod device_sums;
pub mod device_wall_patches;
pub mod device_wall_placement;
pub mod device_wall_slots;
mod device_walls;
pub mod driver;
pub mod host;
pub mod nvrtc;
#[cfg(test)]
mod polyhedra_tests;
mod readback;
pub mod stepper;

/// A source file of `kernels/`.
#[derive(Debug)]
pub struct KernelFile {
    /// Its name in `kernels/`.
    pub name: &'static str,
    /// Its text.
    pub source: &'static str,
    /// The headers it is compiled after, in order.
    pub headers: &'static [&'static KernelFile],
}

/// Vectors and quaternions with nalgebra's operations: every kernel file's first
/// header.
pub static VEC: KernelFile = KernelFile {
    name: "vec.cuh",
    source: include_str!("../../../kernels/vec.cuh"),
    headers: &[],
};

/// The Hertz–Mindlin law of round contacts.
pub static CONTACT: KernelFile = KernelFile {
    name: "contact.cuh",
    source: include_str!("../../../kernels/contact.cuh"),
    headers: &[],
};

/// The exact overlap of two convex polyhedra (the bit-mask path).
pub static OVERLAP: KernelFile = KernelFile {
    name: "overlap.cuh",
    source: include_str!("../../../kernels/overlap.cuh"),
    headers: &[],
};

/// The geometry of a sphere's contacts: with a sphere, with a convex polyhedron.
pub static ROUND_GEOMETRY: KernelFile = KernelFile {
    name: "round_geometry.cuh",
    source: include_str!("../../../kernels/round_geometry.cuh"),
    headers: &[],
};

/// The volume-based contact law of polyhedra.
pub static VOLUME_LAW: KernelFile = KernelFile {
    name: "volume_law.cuh",
    source: include_str!("../../../kernels/volume_law.cuh"),
    headers: &[],
};

/// How a rigid body moves at a contact: angular velocity, inverse mass at a point.
pub static BODY: KernelFile = KernelFile {
    name: "body.cuh",
    source: include_str!("../../../kernels/body.cuh"),
    headers: &[],
};

/// Wall facets: the closest point, the plane key, the wall contacts' slots.
pub static TRIANGLE: KernelFile = KernelFile {
    name: "triangle.cuh",
    source: include_str!("../../../kernels/triangle.cuh"),
    headers: &[],
};

/// The overlap of a convex polyhedron with the prism under a wall facet.
pub static FACET: KernelFile = KernelFile {
    name: "facet.cuh",
    source: include_str!("../../../kernels/facet.cuh"),
    headers: &[],
};

/// The facets of a wall near a particle, through the wall's facet grid.
pub static FACET_GRID: KernelFile = KernelFile {
    name: "facet_grid.cuh",
    source: include_str!("../../../kernels/facet_grid.cuh"),
    headers: &[],
};

/// A polyhedron's facet overlaps summed into patches by plane.
pub static WALL_PATCHES: KernelFile = KernelFile {
    name: "wall_patches.cuh",
    source: include_str!("../../../kernels/wall_patches.cuh"),
    headers: &[],
};

/// The kernel files, each compiled to one module.
pub static FILES: [KernelFile; 10] = [
    KernelFile {
        name: "integrate.cu",
        source: include_str!("../../../kernels/integrate.cu"),
        headers: &[&VEC],
    },
    KernelFile {
        name: "list.cu",
        source: include_str!("../../../kernels/list.cu"),
        headers: &[&VEC],
    },
    KernelFile {
        name: "scan.cu",
        source: include_str!("../../../kernels/scan.cu"),
        headers: &[&VEC],
    },
    KernelFile {
        name: "spheres.cu",
        source: include_str!("../../../kernels/spheres.cu"),
        headers: &[&VEC, &CONTACT],
    },
    KernelFile {
        name: "walls.cu",
        source: include_str!("../../../kernels/walls.cu"),
        headers: &[&VEC, &CONTACT, &BODY, &TRIANGLE, &VOLUME_LAW, &FACET_GRID],
    },
    KernelFile {
        name: "sums.cu",
        source: include_str!("../../../kernels/sums.cu"),
        headers: &[&VEC, &CONTACT],
    },
    KernelFile {
        name: "halo.cu",
        source: include_str!("../../../kernels/halo.cu"),
        headers: &[&VEC, &CONTACT],
    },
    KernelFile {
        name: "figures.cu",
        source: include_str!("../../../kernels/figures.cu"),
        headers: &[&VEC, &CONTACT],
    },
    KernelFile {
        name: "polyhedra.cu",
        source: include_str!("../../../kernels/polyhedra.cu"),
        headers: &[
            &VEC,
            &CONTACT,
            &BODY,
            &TRIANGLE,
            &OVERLAP,
            &VOLUME_LAW,
            &FACET,
            &FACET_GRID,
            &WALL_PATCHES,
        ],
    },
    KernelFile {
        name: "pairs.cu",
        source: include_str!("../../../kernels/pairs.cu"),
        headers: &[
            &VEC,
            &CONTACT,
            &BODY,
            &TRIANGLE,
            &OVERLAP,
            &ROUND_GEOMETRY,
            &VOLUME_LAW,
        ],
    },
];

/// A kernel of `kernels/`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Kernel {
    /// The opening kick and drift of the owned particles (`integrate.cu`).
    KickDrift,
    /// The closing half kick of the owned particles (`integrate.cu`).
    ClosingKick,
    /// Each particle's bucket of the hashed grid, counted (`list.cu`).
    BinParticles,
    /// Each particle into its bucket's slice (`list.cu`).
    ScatterParticles,
    /// Each particle's partners of higher index, counted (`list.cu`).
    CountPartners,
    /// Each particle's pairs, sorted (`list.cu`).
    WritePartners,
    /// The pairs holding each particle, counted (`list.cu`).
    CountIncident,
    /// The pairs holding each particle, written (`list.cu`).
    FillIncident,
    /// Each particle's incidences, sorted (`list.cu`).
    SortIncident,
    /// The ids of each pair (`list.cu`).
    PairKeys,
    /// Tangential history carried from the old list to the new (`list.cu`).
    CarryHistory,
    /// Whether any particle moved half a skin since the build (`list.cu`).
    MovedTooFar,
    /// A copy of doubles (`list.cu`).
    CopyDoubles,
    /// The prefix sum's chunk totals (`scan.cu`).
    ScanChunkTotals,
    /// The prefix sum's chunk offsets (`scan.cu`).
    ScanChunkOffsets,
    /// The prefix sum's last pass (`scan.cu`).
    ScanApply,
    /// Words set to zero (`scan.cu`).
    ZeroWords,
    /// A copy of words (`scan.cu`).
    CopyWords,
    /// The Hertz–Mindlin contacts of sphere pairs (`spheres.cu`).
    SphereContacts,
    /// Each particle's weight and pair forces (`spheres.cu`).
    GatherForces,
    /// The Hertz–Mindlin contacts of spheres with wall facets (`walls.cu`).
    SphereWalls,
    /// The walls' forces, torques and facet forces, first pass (`walls.cu`).
    WallSumRows,
    /// Each particle's wall contacts' energy terms (`walls.cu`).
    WallEnergyTerms,
    /// The pairs' energy terms, folded into partial sums (`sums.cu`).
    PairEnergyPartials,
    /// A pass of the deterministic sums (`sums.cu`).
    SumRecords,
    /// The states of the particles sent as ghosts, packed (`halo.cu`).
    PackStates,
    /// The ghosts' states received, unpacked into their slots (`halo.cu`).
    UnpackGhostStates,
    /// A pass of the deterministic sums taking each column's largest (`sums.cu`).
    MaxRecords,
    /// Each owned particle's share of the run's figures (`figures.cu`).
    ParticleFigures,
    /// The overlap of each pair of convex polyhedra at its pose (`polyhedra.cu`).
    PolyhedronOverlaps,
    /// The contacts of the candidate pairs of any world but spheres under
    /// Hertz–Mindlin alone (`pairs.cu`).
    PairContacts,
    /// The overlap of polyhedra with the prisms under wall facets (`polyhedra.cu`).
    PolyhedronFacets,
    /// Each polyhedron's patches against the walls (`polyhedra.cu`).
    PolyhedronWallPatches,
    /// The volume law's contacts of each polyhedron's wall patches (`polyhedra.cu`).
    PolyhedronWallContacts,
    /// The walls' forces, torques and facet forces of polyhedra, first pass
    /// (`polyhedra.cu`).
    PolyhedronWallSumRows,
}

impl Kernel {
    /// Every kernel.
    pub const ALL: [Kernel; 35] = [
        Kernel::KickDrift,
        Kernel::ClosingKick,
        Kernel::BinParticles,
        Kernel::ScatterParticles,
        Kernel::CountPartners,
        Kernel::WritePartners,
        Kernel::CountIncident,
        Kernel::FillIncident,
        Kernel::SortIncident,
        Kernel::PairKeys,
        Kernel::CarryHistory,
        Kernel::MovedTooFar,
        Kernel::CopyDoubles,
        Kernel::ScanChunkTotals,
        Kernel::ScanChunkOffsets,
        Kernel::ScanApply,
        Kernel::ZeroWords,
        Kernel::CopyWords,
        Kernel::SphereContacts,
        Kernel::GatherForces,
        Kernel::SphereWalls,
        Kernel::WallSumRows,
        Kernel::WallEnergyTerms,
        Kernel::PairEnergyPartials,
        Kernel::SumRecords,
        Kernel::PackStates,
        Kernel::UnpackGhostStates,
        Kernel::MaxRecords,
        Kernel::ParticleFigures,
        Kernel::PolyhedronOverlaps,
        Kernel::PairContacts,
        Kernel::PolyhedronFacets,
        Kernel::PolyhedronWallPatches,
        Kernel::PolyhedronWallContacts,
        Kernel::PolyhedronWallSumRows,
    ];

    /// Its name in the source (`extern "C"`, so the PTX entry has it too).
    pub fn name(self) -> &'static str {
        match self {
            Kernel::KickDrift => "kick_drift",
            Kernel::ClosingKick => "closing_kick",
            Kernel::BinParticles => "bin_particles",
            Kernel::ScatterParticles => "scatter_particles",
            Kernel::CountPartners => "count_partners",
            Kernel::WritePartners => "write_partners",
            Kernel::CountIncident => "count_incident",
            Kernel::FillIncident => "fill_incident",
            Kernel::SortIncident => "sort_incident",
            Kernel::PairKeys => "pair_keys",
            Kernel::CarryHistory => "carry_history",
            Kernel::MovedTooFar => "moved_too_far",
            Kernel::CopyDoubles => "copy_doubles",
            Kernel::ScanChunkTotals => "scan_chunk_totals",
            Kernel::ScanChunkOffsets => "scan_chunk_offsets",
            Kernel::ScanApply => "scan_apply",
            Kernel::ZeroWords => "zero_words",
            Kernel::CopyWords => "copy_words",
            Kernel::SphereContacts => "sphere_contacts",
            Kernel::GatherForces => "gather_forces",
            Kernel::SphereWalls => "sphere_walls",
            Kernel::WallSumRows => "wall_sum_rows",
            Kernel::WallEnergyTerms => "wall_energy_terms",
            Kernel::PairEnergyPartials => "pair_energy_partials",
            Kernel::SumRecords => "sum_records",
            Kernel::PackStates => "pack_states",
            Kernel::UnpackGhostStates => "unpack_ghost_states",
            Kernel::MaxRecords => "max_records",
            Kernel::ParticleFigures => "particle_figures",
            Kernel::PolyhedronOverlaps => "polyhedron_overlaps",
            Kernel::PairContacts => "pair_contacts",
            Kernel::PolyhedronFacets => "polyhedron_facets",
            Kernel::PolyhedronWallPatches => "polyhedron_wall_patches",
            Kernel::PolyhedronWallContacts => "polyhedron_wall_contacts",
            Kernel::PolyhedronWallSumRows => "polyhedron_wall_sum_rows",
        }
    }

    /// The source file that holds it.
    pub fn file(self) -> &'static KernelFile {
        use Kernel::*;
        let index = match self {
            KickDrift | ClosingKick => 0,
            BinParticles | ScatterParticles | CountPartners | WritePartners | CountIncident
            | FillIncident | SortIncident | PairKeys | CarryHistory | MovedTooFar | CopyDoubles => {
                1
            }
            ScanChunkTotals | ScanChunkOffsets | ScanApply | ZeroWords | CopyWords => 2,
            SphereContacts | GatherForces => 3,
            SphereWalls | WallSumRows | WallEnergyTerms => 4,
            PairEnergyPartials | SumRecords | MaxRecords => 5,
            PackStates | UnpackGhostStates => 6,
            ParticleFigures => 7,
            PolyhedronOverlaps
            | PolyhedronFacets
            | PolyhedronWallPatches
            | PolyhedronWallContacts
            | PolyhedronWallSumRows => 8,
            PairContacts => 9,
        };
        &FILES[index]
    }
}

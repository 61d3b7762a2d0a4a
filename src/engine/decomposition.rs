//! Domain decomposition by recursive coordinate bisection (RCB): the space split
//! into one axis-aligned box per rank so that each box holds an equal share of the
//! particles' cost, and the ranks a particle must be copied to as a ghost.
//!
//! **Bisection.** A set of particles and a range of `n` ranks is split across the
//! longest extent of the particles' centroids, at the plane where the cost on the
//! low side reaches `⌊n/2⌋/n` of the set's (so odd rank counts split unevenly, in
//! proportion), and each side is bisected again until one rank is left. A plane
//! lies midway between two consecutive centroids, so no centroid lies on one, and a
//! box is half-open (`lo ≤ x < hi`); the outermost boxes reach to infinity, so every
//! point of space has exactly one owner, also a particle that leaves the cloud.
//!
//! **Independent of storage order.** Centroids are ordered by their coordinates
//! alone (the other two break ties), so the same particles stored in any order give
//! the same boxes: the split depends on the state, not on where a rank keeps it.
//!
//! **Ghosts.** A particle owned by one rank is copied to every other rank whose box
//! comes within `reach` of its centroid. With `reach` the largest distance at which
//! two centroids can still be in contact within a list interval (twice the largest
//! bounding radius plus the skin), every partner a rank's particle can meet is there.

use nalgebra::Point3;

use crate::Real;

/// A box of space owned by one rank: the points `x` with `lo ≤ x < hi` per axis
/// (bounds may be infinite).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Subdomain {
    /// Lower corner (inclusive).
    pub lo: [Real; 3],
    /// Upper corner (exclusive).
    pub hi: [Real; 3],
}

impl Subdomain {
    const EVERYWHERE: Subdomain = Subdomain {
        lo: [Real::NEG_INFINITY; 3],
        hi: [Real::INFINITY; 3],
    };

    /// Whether the box holds `x`.
    pub fn contains(&self, x: &Point3<Real>) -> bool {
        (0..3).all(|a| self.lo[a] <= x[a] && x[a] < self.hi[a])
    }

    /// Euclidean distance from `x` to the box (0 inside).
    pub fn distance(&self, x: &Point3<Real>) -> Real {
        (0..3)
            .map(|a| (self.lo[a] - x[a]).max(x[a] - self.hi[a]).max(0.0).powi(2))
            .sum::<Real>()
            .sqrt()
    }
}

/// A node of the bisection tree.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Node {
    /// Points with `x[axis] < at` go to `low`, the others to `high` (node indices).
    Split {
        axis: usize,
        at: Real,
        low: usize,
        high: usize,
    },
    /// A rank's box.
    Leaf(usize),
}

/// The boxes of every rank and the tree that finds a point's owner.
///
/// Invariant: the boxes tile space (every point lies in exactly one), box `r`
/// belongs to rank `r`, and descending the tree from node 0 ends at the leaf of the
/// box that holds the point.
#[derive(Clone, Debug, PartialEq)]
pub struct Decomposition {
    boxes: Vec<Subdomain>,
    nodes: Vec<Node>,
}

impl Decomposition {
    /// Bisects `centroids` weighted by `cost` (one per centroid, non-negative) into
    /// `ranks` boxes (at least one).
    pub fn bisect(centroids: &[Point3<Real>], cost: &[Real], ranks: usize) -> Self {
        assert_eq!(centroids.len(), cost.len(), "one cost per centroid");
        let mut d = Decomposition {
            boxes: vec![Subdomain::EVERYWHERE; ranks.max(1)],
            nodes: Vec::new(),
        };
        let mut items: Vec<usize> = (0..centroids.len()).collect();
        d.split(
            centroids,
            cost,
            &mut items,
            0..ranks.max(1),
            Subdomain::EVERYWHERE,
        );
        d
    }

    /// Number of ranks.
    pub fn ranks(&self) -> usize {
        self.boxes.len()
    }

    /// Rank `r`'s box.
    pub fn subdomain(&self, r: usize) -> &Subdomain {
        &self.boxes[r]
    }

    /// The rank whose box holds `x`.
    pub fn owner(&self, x: &Point3<Real>) -> usize {
        let mut node = 0;
        loop {
            match self.nodes[node] {
                Node::Leaf(rank) => return rank,
                Node::Split {
                    axis,
                    at,
                    low,
                    high,
                } => node = if x[axis] < at { low } else { high },
            }
        }
    }

    /// The ranks other than `owner` whose boxes come within `reach` of `x`, in rank
    /// order: where a particle at `x` owned by `owner` is a ghost.
    pub fn ghost_ranks(&self, x: &Point3<Real>, owner: usize, reach: Real) -> Vec<usize> {
        (0..self.ranks())
            .filter(|&r| r != owner && self.boxes[r].distance(x) <= reach)
            .collect()
    }

    /// The largest rank cost over the mean (1 when balanced; what rebalancing is
    /// judged by).
    pub fn imbalance(&self, centroids: &[Point3<Real>], cost: &[Real]) -> Real {
        let mut per_rank = vec![0.0; self.ranks()];
        for (x, c) in centroids.iter().zip(cost) {
            per_rank[self.owner(x)] += c;
        }
        let mean = per_rank.iter().sum::<Real>() / self.ranks() as Real;
        let most = per_rank.iter().copied().fold(0.0, Real::max);
        if mean > 0.0 { most / mean } else { 1.0 }
    }

    /// Adds the subtree of `ranks` over `items` (centroid indices) in `within`;
    /// returns its node index.
    fn split(
        &mut self,
        centroids: &[Point3<Real>],
        cost: &[Real],
        items: &mut [usize],
        ranks: std::ops::Range<usize>,
        within: Subdomain,
    ) -> usize {
        let node = self.nodes.len();
        let n = ranks.len();
        if n == 1 {
            self.boxes[ranks.start] = within;
            self.nodes.push(Node::Leaf(ranks.start));
            return node;
        }
        self.nodes.push(Node::Leaf(usize::MAX)); // replaced below
        let axis = longest_extent(centroids, items, &within);
        items.sort_unstable_by(|&i, &j| {
            let (a, b) = (&centroids[i], &centroids[j]);
            let key = |p: &Point3<Real>| [p[axis], p[(axis + 1) % 3], p[(axis + 2) % 3]];
            let (ka, kb) = (key(a), key(b));
            ka[0]
                .total_cmp(&kb[0])
                .then(ka[1].total_cmp(&kb[1]))
                .then(ka[2].total_cmp(&kb[2]))
        });
        let low_ranks = n / 2;
        let at = split_plane(
            centroids,
            cost,
            items,
            axis,
            low_ranks as Real / n as Real,
            &within,
        );
        let cut = items.partition_point(|&i| centroids[i][axis] < at);
        let (mut low_box, mut high_box) = (within, within);
        low_box.hi[axis] = at;
        high_box.lo[axis] = at;
        let (low_items, high_items) = items.split_at_mut(cut);
        let mid = ranks.start + low_ranks;
        let low = self.split(centroids, cost, low_items, ranks.start..mid, low_box);
        let high = self.split(centroids, cost, high_items, mid..ranks.end, high_box);
        self.nodes[node] = Node::Split {
            axis,
            at,
            low,
            high,
        };
        node
    }
}

/// The axis along which the items' centroids spread most; for no items, the
/// box's longest finite side, else x.
fn longest_extent(centroids: &[Point3<Real>], items: &[usize], within: &Subdomain) -> usize {
    let spread = |a: usize| -> Real {
        if items.is_empty() {
            let side = within.hi[a] - within.lo[a];
            return if side.is_finite() { side } else { 0.0 };
        }
        let (lo, hi) = items
            .iter()
            .fold((Real::INFINITY, Real::NEG_INFINITY), |(lo, hi), &i| {
                (lo.min(centroids[i][a]), hi.max(centroids[i][a]))
            });
        hi - lo
    };
    (0..3)
        .max_by(|&a, &b| spread(a).total_cmp(&spread(b)).then(b.cmp(&a)))
        .unwrap_or(0)
}

/// The plane across `axis` below which the cost of the sorted items comes nearest
/// `fraction` of theirs (counts where they cost nothing), midway between two
/// consecutive distinct coordinates. Items all on one coordinate go above it; no
/// items, the box's finite side (an empty box below).
fn split_plane(
    centroids: &[Point3<Real>],
    cost: &[Real],
    items: &[usize],
    axis: usize,
    fraction: Real,
    within: &Subdomain,
) -> Real {
    let coordinate = |k: usize| centroids[items[k]][axis];
    if items.is_empty() {
        return [within.lo[axis], within.hi[axis]]
            .into_iter()
            .find(|v| v.is_finite())
            .unwrap_or(0.0);
    }
    let total: Real = items.iter().map(|&i| cost[i]).sum();
    let weight = |i: usize| if total > 0.0 { cost[i] } else { 1.0 };
    let goal = fraction * items.iter().map(|&i| weight(i)).sum::<Real>();
    let (mut below, mut best) = (0.0, None::<(Real, usize)>);
    for k in 1..items.len() {
        below += weight(items[k - 1]);
        let miss = (below - goal).abs();
        if coordinate(k - 1) < coordinate(k) && best.is_none_or(|(b, _)| miss < b) {
            best = Some((miss, k));
        }
    }
    match best {
        Some((_, k)) => 0.5 * (coordinate(k - 1) + coordinate(k)),
        None => coordinate(0),
    }
}

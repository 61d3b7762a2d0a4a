//! The shortest contact period over every pair of body types, without visiting every
//! pair: a branch and bound over two trees of the types' features.
//!
//! The types of one material and kind (sphere or polyhedron) form a tree, split
//! at the median of the feature that varies most (`E/R`, `1/m`, flatness, on a log
//! scale) down to leaves of [`LEAF`] types. Each node holds the envelope of its
//! types ([`Features::envelope`]), whose period with another node's envelope bounds
//! from below every period between their members ([`Laws::bound`]). Pairs of nodes
//! are taken from a queue, loosest bound first, and split until they are pairs of
//! leaves, which are evaluated type by type; the search stops when the loosest bound
//! left cannot beat the shortest period found. Its answer is the full O(types²)
//! search's (tested); its cost, when the bounds separate the types, O(types · log
//! types).

use std::cmp::{Ordering, Reverse};
use std::collections::BinaryHeap;

use super::{Features, Laws};
use crate::Real;

/// Types per leaf.
const LEAF: usize = 8;

/// A node: the envelope of `types[range]`, and its two halves unless a leaf.
struct Node {
    envelope: Features,
    range: std::ops::Range<usize>,
    children: Option<(usize, usize)>,
}

/// The trees of one set of types: `types` is a permutation of their indices, each
/// node a contiguous run of it.
struct Forest {
    nodes: Vec<Node>,
    types: Vec<usize>,
    roots: Vec<usize>,
}

impl Forest {
    fn new(features: &[Features]) -> Self {
        let mut forest = Forest {
            nodes: Vec::new(),
            types: (0..features.len()).collect(),
            roots: Vec::new(),
        };
        // One run per (material, kind).
        let group = |f: &Features| (f.material, f.is_sphere());
        forest.types.sort_by_key(|&i| (group(&features[i]), i));
        let mut start = 0;
        while start < forest.types.len() {
            let key = group(&features[forest.types[start]]);
            let end = start
                + forest.types[start..]
                    .iter()
                    .take_while(|&&i| group(&features[i]) == key)
                    .count();
            let root = forest.build(features, start..end);
            forest.roots.push(root);
            start = end;
        }
        forest
    }

    fn build(&mut self, features: &[Features], range: std::ops::Range<usize>) -> usize {
        let members = &mut self.types[range.clone()];
        let envelope = members[1..]
            .iter()
            .fold(features[members[0]], |e, &i| e.envelope(&features[i]));
        let index = self.nodes.len();
        self.nodes.push(Node {
            envelope,
            range: range.clone(),
            children: None,
        });
        if members.len() > LEAF {
            let keys: [fn(&Features) -> Real; 3] = [
                |f| f.stiffness,
                |f| 1.0 / f.mass,
                |f| if f.is_sphere() { f.sphere } else { f.flatness },
            ];
            let spread = |key: &fn(&Features) -> Real| {
                let (lo, hi) = members.iter().fold((Real::MAX, Real::MIN), |(lo, hi), &i| {
                    let v = key(&features[i]).ln();
                    (lo.min(v), hi.max(v))
                });
                hi - lo
            };
            let key = keys
                .iter()
                .max_by(|a, b| spread(a).total_cmp(&spread(b)))
                .expect("three keys");
            let half = members.len() / 2;
            members.select_nth_unstable_by(half, |&a, &b| {
                key(&features[a]).total_cmp(&key(&features[b]))
            });
            let middle = range.start + half;
            let left = self.build(features, range.start..middle);
            let right = self.build(features, middle..range.end);
            self.nodes[index].children = Some((left, right));
        }
        index
    }
}

/// A pair of nodes with the lower bound of its members' periods.
struct Candidate {
    bound: Real,
    a: usize,
    b: usize,
}

impl PartialEq for Candidate {
    fn eq(&self, other: &Self) -> bool {
        self.cmp(other) == Ordering::Equal
    }
}
impl Eq for Candidate {}
impl PartialOrd for Candidate {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}
impl Ord for Candidate {
    fn cmp(&self, other: &Self) -> Ordering {
        self.bound
            .total_cmp(&other.bound)
            .then((self.a, self.b).cmp(&(other.a, other.b)))
    }
}

/// The shortest period of a contact between two body types, as `(period, i, j)` with
/// `i ≤ j` (the first such pair in row order among equals).
pub(super) fn shortest_pair_period(
    features: &[Features],
    laws: &Laws,
) -> Option<(Real, usize, usize)> {
    let forest = Forest::new(features);
    let nodes = &forest.nodes;
    let mut queue = BinaryHeap::new();
    let push = |queue: &mut BinaryHeap<Reverse<Candidate>>, a: usize, b: usize| {
        if let Some(bound) = laws.bound(&nodes[a].envelope, &nodes[b].envelope) {
            let (a, b) = (a.min(b), a.max(b));
            queue.push(Reverse(Candidate { bound, a, b }));
        }
    };
    for (k, &a) in forest.roots.iter().enumerate() {
        for &b in &forest.roots[k..] {
            push(&mut queue, a, b);
        }
    }
    let mut best: Option<(Real, usize, usize)> = None;
    while let Some(Reverse(c)) = queue.pop() {
        // Equal bounds are still searched: a pair of equal period and lower indices
        // is the one to name.
        if best.is_some_and(|b| c.bound > b.0) {
            break;
        }
        let (na, nb) = (&nodes[c.a], &nodes[c.b]);
        match (na.children, nb.children) {
            (None, None) => {
                for (k, &i) in forest.types[na.range.clone()].iter().enumerate() {
                    // A node paired with itself: each pair once.
                    let partners = if c.a == c.b {
                        &forest.types[na.range.start + k..na.range.end]
                    } else {
                        &forest.types[nb.range.clone()]
                    };
                    for &j in partners {
                        let Some(period) = laws.period(&features[i], &features[j]) else {
                            continue;
                        };
                        let candidate = (period, i.min(j), i.max(j));
                        if best.is_none_or(|b| {
                            period < b.0
                                || (period == b.0 && (candidate.1, candidate.2) < (b.1, b.2))
                        }) {
                            best = Some(candidate);
                        }
                    }
                }
            }
            _ if c.a == c.b => {
                let (l, r) = na.children.expect("an inner node");
                push(&mut queue, l, l);
                push(&mut queue, l, r);
                push(&mut queue, r, r);
            }
            _ => {
                // Split the larger node (or the one that can be split).
                let split_a = match (na.children, nb.children) {
                    (Some(_), None) => true,
                    (None, Some(_)) => false,
                    _ => na.range.len() >= nb.range.len(),
                };
                let (split, keep) = if split_a { (na, c.b) } else { (nb, c.a) };
                let (l, r) = split.children.expect("an inner node");
                push(&mut queue, l, keep);
                push(&mut queue, r, keep);
            }
        }
    }
    best
}

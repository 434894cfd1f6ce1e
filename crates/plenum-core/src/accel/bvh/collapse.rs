//! The binary tree collapsed into nodes of up to eight children at the least SAH cost
//! (Ylitie, Karras and Laine 2017), then flattened into the node array.

use super::{leaf_reference, Aabb, LeafSize, Node, EMPTY, NODE_BYTES, WIDTH};

pub(super) enum BuildNode {
    Leaf {
        bounds: Aabb,
        start: u32,
        count: u32,
    },
    Inner {
        bounds: Aabb,
        children: Vec<BuildNode>,
    },
}

impl BuildNode {
    pub(super) fn bounds(&self) -> &Aabb {
        match self {
            BuildNode::Leaf { bounds, .. } | BuildNode::Inner { bounds, .. } => bounds,
        }
    }
}

/// Appends a node holding `children` (at most eight), then their subtrees depth-first,
/// and returns its reference.
pub(super) fn flatten_children(nodes: &mut Vec<Node>, children: &[BuildNode]) -> u32 {
    let index = nodes.len();
    assert!(
        index < (u32::MAX / NODE_BYTES) as usize,
        "too many nodes for a BVH node reference"
    );
    let mut node = Node {
        planes: [
            [f32::INFINITY; WIDTH],
            [f32::INFINITY; WIDTH],
            [f32::INFINITY; WIDTH],
            [f32::NEG_INFINITY; WIDTH],
            [f32::NEG_INFINITY; WIDTH],
            [f32::NEG_INFINITY; WIDTH],
        ],
        children: [EMPTY; WIDTH],
        used: (1 << children.len()) - 1,
    };
    for (slot, child) in children.iter().enumerate() {
        let b = child.bounds();
        for a in 0..3 {
            node.planes[a][slot] = b.lo[a];
            node.planes[3 + a][slot] = b.hi[a];
        }
    }
    nodes.push(node);
    for (slot, child) in children.iter().enumerate() {
        let reference = match child {
            BuildNode::Leaf { start, count, .. } => {
                leaf_reference(*start as usize, *count as usize)
            }
            BuildNode::Inner { children, .. } => flatten_children(nodes, children),
        };
        nodes[index].children[slot] = reference;
    }
    index as u32 * NODE_BYTES
}

/// A node of the binary tree, planned for its collapse into eight-wide nodes by the
/// optimal collapse of Ylitie, Karras and Laine (2017): bottom up, each node keeps the
/// least SAH cost of its subtree spread over at most j slots of a wide node, for j up to
/// eight; top down, the root then takes the cheapest plan and each node's slots are shared
/// out as planned. Costs are in units of a node visit times its box's half area; a leaf
/// costs as [`LeafSize`] says.
pub(super) struct Binary {
    pub(super) bounds: Aabb,
    pub(super) start: u32,
    pub(super) count: u32,
    pub(super) children: Option<Box<[Binary; 2]>>,
    /// `cost[j - 1]`: the subtree's least cost in at most `j` slots.
    pub(super) cost: [f32; WIDTH],
    /// `split[j - 1]`: how many of those `j` slots the first child's subtree takes in the
    /// cheapest plan, or 0 where the subtree takes one slot.
    pub(super) split: [u8; WIDTH],
    /// In one slot: a leaf, or else a node whose eight slots the children share as
    /// `node_split` says.
    pub(super) leaf: bool,
    pub(super) node_split: u8,
}

impl Binary {
    pub(super) fn planned(
        bounds: Aabb,
        start: usize,
        count: usize,
        children: Option<Box<[Binary; 2]>>,
        leaf: &LeafSize,
    ) -> Binary {
        let area = bounds.half_area();
        let leaf_cost = if count <= leaf.max_leaf {
            area * leaf.cost(count)
        } else {
            f32::INFINITY
        };
        let mut plan = Binary {
            bounds,
            start: start as u32,
            count: count as u32,
            children: None,
            cost: [leaf_cost; WIDTH],
            split: [0; WIDTH],
            leaf: true,
            node_split: 0,
        };
        let Some(children) = children else {
            return plan;
        };
        let [first, second] = &*children;
        // The least cost in j slots, at least one for each child, and the first one's share
        // (one slot where no cost is finite: boxes too large for f32 areas).
        let mut shared = [(f32::INFINITY, 1u8); WIDTH];
        for j in 2..=WIDTH {
            for k in 1..j {
                let cost = first.cost[k - 1] + second.cost[j - k - 1];
                if cost < shared[j - 1].0 {
                    shared[j - 1] = (cost, k as u8);
                }
            }
        }
        let node_cost = area + shared[WIDTH - 1].0;
        plan.leaf = count <= leaf.max_leaf && leaf_cost <= node_cost;
        plan.node_split = shared[WIDTH - 1].1;
        let one_slot = if plan.leaf { leaf_cost } else { node_cost };
        for j in 1..=WIDTH {
            (plan.cost[j - 1], plan.split[j - 1]) = if j > 1 && shared[j - 1].0 < one_slot {
                shared[j - 1]
            } else {
                (one_slot, 0)
            };
        }
        plan.children = Some(children);
        plan
    }

    /// The subtree in one slot, as planned: a leaf, or a node.
    pub(super) fn into_wide(self) -> BuildNode {
        match self.children {
            Some(children) if !self.leaf => {
                let mut slots = Vec::with_capacity(WIDTH);
                let [first, second] = *children;
                let k = self.node_split as usize;
                first.into_slots(k, &mut slots);
                second.into_slots(WIDTH - k, &mut slots);
                BuildNode::Inner {
                    bounds: self.bounds,
                    children: slots,
                }
            }
            _ => BuildNode::Leaf {
                bounds: self.bounds,
                start: self.start,
                count: self.count,
            },
        }
    }

    /// Appends the subtree as planned for at most `slots` slots.
    pub(super) fn into_slots(self, slots: usize, out: &mut Vec<BuildNode>) {
        let k = self.split[slots - 1] as usize;
        if k == 0 {
            out.push(self.into_wide());
            return;
        }
        let [first, second] = *self
            .children
            .expect("slots are shared only between children");
        first.into_slots(k, out);
        second.into_slots(slots - k, out);
    }
}

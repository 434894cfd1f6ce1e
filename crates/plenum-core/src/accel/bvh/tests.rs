use super::build::*;
use super::collapse::*;
use super::traverse::*;
use super::*;
use crate::math::Ray;

/// Leaves of at most `max_leaf` items, `block` to a test, each test costing a node visit.
fn sizes(max_leaf: usize, block: usize) -> LeafSize {
    LeafSize {
        max_leaf,
        block,
        leaf_cost: 1.0,
        block_cost: 1.0,
    }
}

/// The cost of a wide subtree, worked out from the tree itself.
fn wide_cost(node: &BuildNode, leaf: &LeafSize) -> f32 {
    match node {
        BuildNode::Leaf { bounds, count, .. } => bounds.half_area() * leaf.cost(*count as usize),
        BuildNode::Inner { bounds, children } => {
            bounds.half_area() + children.iter().map(|c| wide_cost(c, leaf)).sum::<f32>()
        }
    }
}

/// Every collapse of a binary subtree into wide slots, as (cost, slots), by exhaustive
/// enumeration: a leaf where it may be one; each collapse of the first child beside each
/// of the second's; and a node over the cheapest of those that fit in its slots.
fn every_collapse(node: &Binary, leaf: &LeafSize) -> Vec<(f32, usize)> {
    let area = node.bounds.half_area();
    let mut all = Vec::new();
    if node.count as usize <= leaf.max_leaf {
        all.push((area * leaf.cost(node.count as usize), 1));
    }
    if let Some(children) = &node.children {
        let second = every_collapse(&children[1], leaf);
        let mut fitting = f32::INFINITY;
        for (a, m) in every_collapse(&children[0], leaf) {
            for &(b, n) in &second {
                if m + n <= WIDTH {
                    all.push((a + b, m + n));
                    fitting = fitting.min(a + b);
                }
            }
        }
        all.push((area + fitting, 1));
    }
    all
}

/// `n` boxes at random (a fixed linear congruential sequence from `seed`) in the unit
/// cube, of sizes from 0.01 to 0.3.
fn random_boxes(n: usize, seed: u64) -> Vec<Bounds3> {
    use crate::math::Vec3;
    let mut state = seed;
    let mut next = move || {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (state >> 40) as f64 / (1u64 << 24) as f64
    };
    (0..n)
        .map(|_| {
            let c = Vec3::new(next(), next(), next());
            let size = Vec3::new(next(), next(), next()) * 0.29 + Vec3::ONE * 0.01;
            Bounds3::new(c, c + size)
        })
        .collect()
}

fn items_of(boxes: &[Bounds3]) -> Vec<Item> {
    boxes
        .iter()
        .enumerate()
        .map(|(i, b)| Item {
            lo: [0, 1, 2].map(|a| b.min[a] as f32),
            hi: [0, 1, 2].map(|a| b.max[a] as f32),
            index: i as u32,
        })
        .collect()
}

/// Boxes along a noisy curve, so leaves of every size occur.
fn curve_boxes() -> Vec<Bounds3> {
    use crate::math::Vec3;
    (0..1000)
        .map(|i| {
            let x = i as f64 * 0.01;
            let c = Vec3::new(x, (7.0 * x).sin(), ((i * 37) % 11) as f64 * 0.05);
            Bounds3::new(c, c + Vec3::ONE * 0.02)
        })
        .collect()
}

#[test]
fn the_sah_cost_counts_nodes_and_leaf_blocks_by_area() {
    use crate::math::Vec3;
    // Two unit cubes nine apart: the root's box is 10 × 1 × 1 (half area 21), each
    // cube's 3. Tested one at a time, the pair is worth splitting: one node (the root,
    // crossed by every ray) and two leaves of one block, each crossed by 3/21 of rays.
    let cube = |x: f64| Bounds3::new(Vec3::new(x, 0.0, 0.0), Vec3::new(x + 1.0, 1.0, 1.0));
    let bvh = Bvh::build(&[cube(0.0), cube(9.0)], sizes(8, 1));
    let cost = bvh.sah_cost(1);
    assert!((cost.nodes - 1.0).abs() < 1e-6, "{cost:?}");
    assert!((cost.leaves - 6.0 / 21.0).abs() < 1e-6, "{cost:?}");
    // Tested four at a time, one leaf of one block holds both: splitting saves nothing.
    let bvh = Bvh::build(&[cube(0.0), cube(9.0)], sizes(8, 4));
    assert_eq!(
        bvh.sah_cost(4),
        SahCost {
            nodes: 1.0,
            leaves: 1.0
        }
    );
    assert_eq!(Bvh::build(&[], sizes(8, 4)).sah_cost(4), SahCost::default());
}

#[test]
fn children_are_visited_nearest_first() {
    use crate::math::Vec3;
    // A row of 300 unit boxes in x, spread out in y and z so that eight-wide nodes hold
    // boxes side by side: a ray down the row must meet every box crossing it in order,
    // whichever way it runs, and any order must still meet them all.
    let boxes: Vec<Bounds3> = (0..300)
        .map(|i| {
            let c = Vec3::new(i as f64 * 1.5, (i % 5) as f64 * 0.1, (i % 3) as f64 * 0.1);
            Bounds3::new(c, c + Vec3::ONE)
        })
        .collect();
    let bvh = Bvh::build(&boxes, sizes(1, 1));
    for (origin, direction) in [(-5.0, 1.0), (500.0, -1.0)] {
        let ray = Ray::new(
            Vec3::new(origin, 0.55, 0.55),
            Vec3::new(direction, 0.0, 0.0),
        );
        let mut met = Vec::new();
        bvh.traverse(&ray, f64::INFINITY, |items, _| {
            met.extend_from_slice(items);
            true
        });
        let mut expected: Vec<u32> = (0..300).collect();
        if direction < 0.0 {
            expected.reverse();
        }
        assert_eq!(met, expected, "direction {direction}");
        // Either coherence hint: the same boxes in the same order.
        let items = LeafItems::<{ std::mem::size_of::<u32>() }>::at(&bvh.order);
        let any_order = |coherence| {
            let mut met = Vec::new();
            bvh.traverse_runs_any_order(&ray, f64::INFINITY, items, coherence, |run, _| {
                met.extend(bvh.order[run].iter().copied());
                true
            });
            met
        };
        let mut any = any_order(Coherence::Incoherent);
        assert_eq!(any_order(Coherence::Coherent), any, "direction {direction}");
        any.sort();
        assert_eq!(any, (0..300).collect::<Vec<u32>>(), "direction {direction}");
    }
}

#[test]
fn padded_order_starts_every_leaf_on_a_block() {
    let boxes = curve_boxes();
    let mut bvh = Bvh::build(&boxes, sizes(8, 4));
    let order = bvh.take_padded_order(4);
    assert_eq!(order.len() % 4, 0);
    let mut seen = vec![0; boxes.len()];
    let mut covered = vec![false; order.len()];
    for node in bvh.nodes.iter() {
        for (slot, &child) in node.children.iter().enumerate() {
            if node.used & (1 << slot) == 0 || !is_leaf(child) {
                continue;
            }
            let (start, count) = leaf_run(child);
            assert_eq!(start % 4, 0, "a leaf starts inside a block");
            for (k, &item) in order[start..start + count.next_multiple_of(4)]
                .iter()
                .enumerate()
            {
                covered[start + k] = true;
                if k < count {
                    seen[item as usize] += 1;
                } else {
                    assert_eq!(item, crate::accel::PAD);
                }
            }
        }
    }
    assert!(
        seen.iter().all(|&n| n == 1),
        "every item in exactly one leaf"
    );
    assert!(covered.iter().all(|&c| c), "no slot outside a leaf");
}

#[test]
fn leaf_references_keep_their_run_apart_from_node_references() {
    for count in 1..=MAX_LEAF_ITEMS {
        for start in [0, 1, 5, 4096, (1 << (32 - START_SHIFT)) - 1] {
            let reference = leaf_reference(start, count);
            assert!(is_leaf(reference));
            assert_eq!(leaf_run(reference), (start, count));
        }
    }
    // Nodes start on cache lines: their offsets never carry the flag.
    for index in [0, 1, 7, 1 << 20] {
        assert!(!is_leaf(index * NODE_BYTES));
    }
    assert!(std::panic::catch_unwind(|| leaf_reference(0, MAX_LEAF_ITEMS + 1)).is_err());
    assert!(std::panic::catch_unwind(|| leaf_reference(1 << 28, 1)).is_err());
}

#[test]
fn embedded_blocks_follow_their_node_and_are_visited_as_before() {
    use crate::math::Vec3;
    let boxes = curve_boxes();
    let mut bvh = Bvh::build(&boxes, sizes(8, 4));
    let order = bvh.take_padded_order(4);
    // Blocks of four item numbers: 16 bytes, one unit.
    let blocks: Vec<[u32; 4]> = order.chunks(4).map(|c| [c[0], c[1], c[2], c[3]]).collect();
    let before = bvh.clone();
    let mut small = bvh.clone();
    assert!(!small.embed_blocks(&blocks, 4, 1024), "over the limit");
    assert!(!small.is_embedded());
    assert!(bvh.embed_blocks(&blocks, 4, EMBED_LIMIT));
    let bytes = bvh.embedded();
    let items_at = |place: usize, count: usize| -> Vec<u32> {
        let run = &bytes[place * EMBED_UNIT..][..count.next_multiple_of(4) * 4];
        run.chunks(4)
            .map(|b| u32::from_ne_bytes(b.try_into().unwrap()))
            .collect()
    };
    // Each node's leaf children, in slot order, right after it.
    let mut seen = vec![0; boxes.len()];
    let mut pending = vec![0usize];
    while let Some(at) = pending.pop() {
        let node: Node = unsafe { std::ptr::read(bytes[at..].as_ptr() as *const Node) };
        let mut next = at + NODE_BYTES as usize;
        for slot in node.slots() {
            let child = node.children[slot];
            if !is_leaf(child) {
                pending.push(child as usize);
                continue;
            }
            let (place, count) = leaf_run(child);
            assert_eq!(
                place * EMBED_UNIT,
                next,
                "a leaf's blocks away from its node"
            );
            // Read as a byte offset from the base (on a cache line's start), the
            // reference names the line the leaf's first block starts on.
            assert_eq!(
                AmongNodes.fetch_address(std::ptr::null(), child) as usize / 64,
                place * EMBED_UNIT / 64
            );
            next += count.div_ceil(4) * EMBED_UNIT;
            let items = items_at(place, count);
            items[..count].iter().for_each(|&i| seen[i as usize] += 1);
            assert!(items[count..].iter().all(|&i| i == crate::accel::PAD));
        }
    }
    assert!(
        seen.iter().all(|&n| n == 1),
        "every item in exactly one leaf"
    );
    assert_eq!(
        bvh.embedded_leaves()
            .iter()
            .map(|&(_, count)| count)
            .sum::<usize>(),
        boxes.len()
    );
    // The same leaves, in the same order, for rays in every direction (seed-free:
    // directions on a spiral).
    let mut visited = 0;
    for k in 0..200 {
        let z = 1.0 - 2.0 * (k as f64 + 0.5) / 200.0;
        let phi = k as f64 * 2.399963;
        let r = (1.0 - z * z).sqrt();
        let direction = Vec3::new(r * phi.cos(), r * phi.sin(), z);
        let ray = Ray::new(Vec3::new(5.0, 0.0, 0.25), direction);
        let mut old = Vec::new();
        let mut new = Vec::new();
        before.traverse_runs(&ray, f64::INFINITY, LeafItems::<4>::at(&order), |run, _| {
            old.extend_from_slice(&order[run]);
            true
        });
        bvh.traverse_runs(
            &ray,
            f64::INFINITY,
            LeafItems::<EMBED_UNIT>::at(bytes),
            |run, _| {
                new.extend(items_at(run.start, run.len()).into_iter().take(run.len()));
                true
            },
        );
        assert_eq!(old, new, "ray {k}");
        visited += old.len();
    }
    assert!(visited > 100, "the rays reach leaves ({visited} items)");
}

#[test]
fn the_collapse_is_the_cheapest_there_is() {
    // Against every collapse, enumerated, of small random sets, for each number of slots
    // up to eight; leaves of up to 8 items in blocks of 4 (as a mesh's) and up to 4
    // items one by one (as a scene's).
    let mesh = LeafSize {
        leaf_cost: 1.25,
        block_cost: 0.25,
        ..sizes(8, 4)
    };
    for (seed, n) in [(1, 3), (2, 7), (3, 10), (4, 12), (5, 12)] {
        for leaf in [mesh, sizes(4, 1)] {
            let mut items = items_of(&random_boxes(n, seed));
            let root = Builder { leaf }.build(&mut items, 0, 0);
            let all = every_collapse(&root, &leaf);
            for j in 1..=WIDTH {
                let least = all
                    .iter()
                    .filter(|&&(_, slots)| slots <= j)
                    .map(|&(cost, _)| cost)
                    .fold(f32::INFINITY, f32::min);
                let planned = root.cost[j - 1];
                assert!(
                    (planned - least).abs() <= 1e-5 * least,
                    "seed {seed}, {j} slots: planned {planned}, least {least}"
                );
            }
        }
    }
}

#[test]
fn boxes_too_large_for_f32_areas_still_make_a_tree() {
    use crate::math::Vec3;
    // Areas overflow to infinity (and 0 · ∞ to NaN): every plan costs the same, and the
    // tree must still hold each item once, in leaves it can name.
    let boxes: Vec<Bounds3> = (0..100)
        .map(|i| {
            let c = Vec3::new(i as f64 * 1e36, 0.0, 0.0);
            Bounds3::new(c - Vec3::ONE * 1e38, c + Vec3::ONE * 1e38)
        })
        .collect();
    let bvh = Bvh::build(&boxes, sizes(4, 1));
    let ray = Ray::new(Vec3::new(0.0, 0.0, -3e38), Vec3::new(0.0, 0.0, 1.0));
    let mut seen = Vec::new();
    bvh.traverse(&ray, f64::INFINITY, |items, _| {
        seen.extend_from_slice(items);
        true
    });
    seen.sort();
    assert_eq!(seen, (0..100).collect::<Vec<u32>>());
}

#[test]
fn the_wide_tree_is_the_plan() {
    // The tree made costs what its plan said, holds every item once, in leaves of at
    // most `max_leaf` and nodes of at most eight.
    fn check(node: &BuildNode, max_leaf: usize, items: &mut Vec<u32>) {
        match node {
            BuildNode::Leaf { start, count, .. } => {
                assert!((1..=max_leaf as u32).contains(count));
                items.extend(*start..start + count);
            }
            BuildNode::Inner { children, .. } => {
                assert!((1..=WIDTH).contains(&children.len()));
                for c in children {
                    check(c, max_leaf, items);
                }
            }
        }
    }
    let leaf = LeafSize {
        leaf_cost: 1.25,
        block_cost: 0.25,
        ..sizes(8, 4)
    };
    for boxes in [curve_boxes(), random_boxes(5000, 9)] {
        let mut items = items_of(&boxes);
        let root = Builder { leaf }.build(&mut items, 0, 0);
        let planned = root.cost[0];
        let wide = root.into_wide();
        let cost = wide_cost(&wide, &leaf);
        assert!(
            (cost - planned).abs() <= 1e-4 * planned,
            "{cost} against {planned}"
        );
        let mut seen = Vec::new();
        check(&wide, 8, &mut seen);
        seen.sort();
        assert_eq!(seen, (0..boxes.len() as u32).collect::<Vec<_>>());
    }
}

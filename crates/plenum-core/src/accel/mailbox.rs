//! Mailboxing (Amanatides & Woo 1987): structures that file one item in several cells stamp
//! each item with the current ray's number when they test it, so that the item is tested
//! once per ray. The stamps live per thread, one array per structure, and are borrowed only
//! for the moment of filtering a cell, so a mesh's structure can be traversed from inside a
//! scene's.

use std::cell::RefCell;
use std::sync::atomic::{AtomicU64, Ordering};

static NEXT_OWNER: AtomicU64 = AtomicU64::new(1);

/// A number naming one structure's stamps.
pub fn new_owner() -> u64 {
    NEXT_OWNER.fetch_add(1, Ordering::Relaxed)
}

struct Stamps {
    owner: u64,
    ray: u32,
    stamps: Vec<u32>,
    /// When this thread last used them, for evicting the least recently used.
    used: u64,
}

/// Candidates handed to the caller at a time.
const CHUNK: usize = 16;

/// How many structures' stamps a thread keeps.
const KEPT: usize = 32;

thread_local! {
    static MAILBOXES: RefCell<(u64, Vec<Stamps>)> = const { RefCell::new((0, Vec::new())) };
}

/// One ray's view of a structure's mailboxes.
pub struct Mailbox {
    owner: u64,
    ray: u32,
    /// Where the stamps were when the ray started: checked, then used without a search.
    slot: std::cell::Cell<usize>,
}

impl Mailbox {
    /// Starts a ray through the structure `owner` holding `items` items.
    pub fn start(owner: u64, items: usize) -> Mailbox {
        MAILBOXES.with(|m| {
            let (clock, boxes) = &mut *m.borrow_mut();
            *clock += 1;
            let slot = match boxes.iter().position(|s| s.owner == owner) {
                Some(i) => i,
                None => {
                    if boxes.len() >= KEPT {
                        let oldest = (0..boxes.len()).min_by_key(|&i| boxes[i].used);
                        boxes.swap_remove(oldest.unwrap_or(0));
                    }
                    boxes.push(Stamps {
                        owner,
                        ray: 0,
                        stamps: vec![0; items],
                        used: 0,
                    });
                    boxes.len() - 1
                }
            };
            let s = &mut boxes[slot];
            s.used = *clock;
            s.ray = s.ray.wrapping_add(1);
            if s.ray == 0 {
                // After 2³² rays the numbers repeat: clear the stamps once.
                s.stamps.fill(0);
                s.ray = 1;
            }
            Mailbox {
                owner,
                ray: s.ray,
                slot: std::cell::Cell::new(slot),
            }
        })
    }

    /// Hands `visit` the items of `cell` this ray has not tested yet (see
    /// [`super::Accel::traverse`]); returns false if `visit` asked to stop.
    pub fn visit_untested(
        &self,
        cell: &[u32],
        t_max: &mut f64,
        visit: &mut impl FnMut(&[u32], &mut f64) -> bool,
    ) -> bool {
        let mut buffer = [0u32; CHUNK];
        let mut rest = cell;
        while !rest.is_empty() {
            let (n, used) = self.filter(rest, &mut buffer);
            rest = &rest[used..];
            if n > 0 && !visit(&buffer[..n], t_max) {
                return false;
            }
        }
        true
    }

    /// Copies to `out` the items of `cell` this ray has not tested yet, stamping them;
    /// returns how many were copied and how many of `cell` were consumed.
    fn filter(&self, cell: &[u32], out: &mut [u32]) -> (usize, usize) {
        MAILBOXES.with(|m| {
            let (clock, boxes) = &mut *m.borrow_mut();
            *clock += 1;
            let ours = |s: &Stamps| s.owner == self.owner && s.ray == self.ray;
            let slot = match boxes.get(self.slot.get()) {
                Some(s) if ours(s) => Some(self.slot.get()),
                _ => boxes.iter().position(ours),
            };
            let Some(s) = slot.map(|i| {
                self.slot.set(i);
                &mut boxes[i]
            }) else {
                // Our stamps were evicted by traversals nested in this one (more than
                // `KEPT` structures in between): test everything rather than skip an item.
                let n = cell.len().min(out.len());
                out[..n].copy_from_slice(&cell[..n]);
                return (n, n);
            };
            s.used = *clock;
            let mut copied = 0;
            let mut consumed = 0;
            for &item in cell {
                if copied == out.len() {
                    break;
                }
                consumed += 1;
                let stamp = &mut s.stamps[item as usize];
                if *stamp != self.ray {
                    *stamp = self.ray;
                    out[copied] = item;
                    copied += 1;
                }
            }
            (copied, consumed)
        })
    }
}

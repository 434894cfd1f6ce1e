//! Mailboxing (Amanatides & Woo 1987): structures that file one item in several cells stamp
//! each item with the current ray's number when they test it, so that the item is tested
//! once per ray. The stamps live per thread, one array per structure, and are borrowed only
//! for the moment of filtering a cell, so a mesh's structure can be traversed from inside a
//! scene's.

use std::cell::RefCell;
use std::rc::Rc;
use std::sync::atomic::{AtomicU64, Ordering};

static NEXT_OWNER: AtomicU64 = AtomicU64::new(1);

/// A number naming one structure's stamps.
pub fn new_owner() -> u64 {
    NEXT_OWNER.fetch_add(1, Ordering::Relaxed)
}

struct Stamps {
    ray: u32,
    stamps: Vec<u32>,
}

/// One structure's stamps on this thread.
struct Entry {
    owner: u64,
    /// When this thread last used them, for evicting the least recently used.
    used: u64,
    stamps: Rc<RefCell<Stamps>>,
}

/// Candidates handed to the caller at a time.
const CHUNK: usize = 16;

/// How many structures' stamps a thread keeps.
const KEPT: usize = 32;

thread_local! {
    static MAILBOXES: RefCell<(u64, Vec<Entry>)> = const { RefCell::new((0, Vec::new())) };
}

/// One ray's view of a structure's mailboxes. It holds the stamps themselves, so filtering a
/// cell needs no thread-local lookup, and an eviction while the ray is under way cannot
/// take them from it.
pub struct Mailbox {
    ray: u32,
    stamps: Rc<RefCell<Stamps>>,
}

impl Mailbox {
    /// A new ray through the structure `owner` of `items` items: a fresh stamp.
    pub fn start(owner: u64, items: usize) -> Mailbox {
        MAILBOXES.with(|m| {
            let (clock, boxes) = &mut *m.borrow_mut();
            *clock += 1;
            let slot = match boxes.iter().position(|e| e.owner == owner) {
                Some(i) => i,
                None => {
                    if boxes.len() >= KEPT {
                        let oldest = (0..boxes.len()).min_by_key(|&i| boxes[i].used);
                        boxes.swap_remove(oldest.unwrap_or(0));
                    }
                    boxes.push(Entry {
                        owner,
                        used: 0,
                        stamps: Rc::new(RefCell::new(Stamps {
                            ray: 0,
                            stamps: vec![0; items],
                        })),
                    });
                    boxes.len() - 1
                }
            };
            let entry = &mut boxes[slot];
            entry.used = *clock;
            let ray = {
                let mut s = entry.stamps.borrow_mut();
                s.ray = s.ray.wrapping_add(1);
                if s.ray == 0 {
                    s.stamps.fill(0);
                    s.ray = 1;
                }
                s.ray
            };
            Mailbox {
                ray,
                stamps: entry.stamps.clone(),
            }
        })
    }

    /// Hands `visit` the items of `cell` this ray has not tested yet, in chunks, and stamps
    /// them; false when `visit` asked to stop.
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

    /// Copies untested items of `cell` into `out` (as many as fit) and stamps them; returns
    /// how many were copied and how many of `cell` were looked at. The stamps are borrowed
    /// only here, never while `visit` runs, so a nested traversal of the same structure
    /// (another ray, with its own stamp) does not conflict; at worst it makes this ray test
    /// an item again.
    fn filter(&self, cell: &[u32], out: &mut [u32; CHUNK]) -> (usize, usize) {
        let mut s = self.stamps.borrow_mut();
        let mut copied = 0;
        let mut consumed = 0;
        for &item in cell {
            if copied == CHUNK {
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
    }
}

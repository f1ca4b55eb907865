//! The particles sorted in memory by cell for long advances (`SORTED_ADVANCE`), and put
//! back in id order: every result is the same, bit for bit, in either order.

use super::Simulation;
use crate::cpu::orientation::RotatedCorners;
use crate::state::gather;

impl Simulation {
    /// Ids for particles added since the last step (in id order: appended), so that
    /// `ids` covers every slot.
    pub(super) fn sync_ids(&mut self) {
        let n = self.particles.len();
        self.ids.truncate(n);
        self.ids.extend(self.ids.len() as u32..n as u32);
    }

    /// Puts the particles, and everything kept per particle or per candidate, in a new
    /// memory order: `order[new] = old` slot. No result depends on the order.
    /// `results`: also the last evaluation's results per candidate (not needed at a
    /// rebuild, which is followed by a new evaluation).
    pub(super) fn permute(&mut self, order: &[u32], results: bool) {
        let mut inverse = vec![0u32; order.len()];
        for (new, &old) in order.iter().enumerate() {
            inverse[old as usize] = new as u32;
        }
        self.particles.permute(order);
        // The corners are laid out by memory slot: again at the next rotation.
        self.corners = RotatedCorners::default();
        if self.velocity.len() == order.len() {
            self.velocity = gather(&self.velocity, order);
        }
        self.ids = gather(&self.ids, order);
        let from = self.neighbours.permute(order, &inverse, &self.ids);
        let c = &mut self.candidates;
        if !results {
            c.kicks.clear();
            c.history.clear();
            c.sub_history.clear();
            c.contacts.clear();
            c.diverging = None;
        } else if c.kicks.len() == from.len() {
            c.kicks = gather(&c.kicks, &from);
            c.history = gather(&c.history, &from);
            if c.sub_history.len() == from.len() {
                c.sub_history = gather(&c.sub_history, &from);
            }
        }
        if c.contacts.len() == from.len() {
            c.contacts = gather(&c.contacts, &from);
        }
        if let Some((k, _)) = &mut c.diverging {
            *k = from.iter().position(|&f| f as usize == *k).unwrap_or(*k);
        }
        self.collect_contacts();
    }

    /// Puts the particles in the cell order of the last sort, if it was made for the
    /// current neighbour list; otherwise the next step rebuilds the list (and sorts).
    pub(super) fn sort_by_cell(&mut self) {
        self.sync_ids();
        let (order, list) = &self.sorted;
        if *list == self.neighbours.rebuilds && order.len() == self.ids.len() {
            // In id order the last sort's ids are the slots to take from.
            let order = order.clone();
            // The last step's results per candidate are not needed: the next step
            // replaces them before anyone reads them.
            self.permute(&order, false);
        } else {
            self.force_rebuild = true;
        }
    }

    /// Puts the particles back in id order; `results`: with the last evaluation's
    /// results per candidate (else the next evaluation must come first).
    pub(super) fn restore_id_order(&mut self, results: bool) {
        if self.ids.iter().enumerate().all(|(k, &id)| id as usize == k) {
            return;
        }
        let mut order = vec![0u32; self.ids.len()];
        for (slot, &id) in self.ids.iter().enumerate() {
            order[id as usize] = slot as u32;
        }
        self.permute(&order, results);
    }
}

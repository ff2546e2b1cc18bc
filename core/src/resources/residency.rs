//! Which brick is in which slot of the pool, across frames: bricks stay resident until their
//! slot is needed, least recently used out first; and the passes of a streamed frame, front
//! to back, resident bricks first where that order allows. Bookkeeping only (no device): the
//! volume applies the moves, and the streaming planner replays them to know what each pass
//! finds resident.

/// A brick no later pass of this frame needs (see [`Slots::place`]).
pub(crate) const NOT_LATER: u32 = u32::MAX;

/// The pool's slots: per brick its slot, per allocated slot its brick, and when each brick
/// was last used (a clock that ticks once per frame and once per streamed pass).
#[derive(Clone, Debug)]
pub(crate) struct Slots {
    slot_of: Vec<Option<u32>>,
    brick_in: Vec<Option<usize>>,
    last_used: Vec<u64>,
    clock: u64,
}

impl Slots {
    pub fn new(bricks: usize) -> Slots {
        Slots {
            slot_of: vec![None; bricks],
            brick_in: Vec::new(),
            last_used: vec![0; bricks],
            clock: 0,
        }
    }

    pub fn slot_of(&self, brick: usize) -> Option<u32> {
        self.slot_of[brick]
    }

    /// Slots allocated (the pool's size in slots).
    pub fn allocated(&self) -> u32 {
        self.brick_in.len() as u32
    }

    /// Ids from 0 to `bricks` (more than before: new ids, not resident; fewer: those past
    /// it are evicted, their slots free).
    pub fn set_bricks(&mut self, bricks: usize) {
        for b in self.brick_in.iter_mut() {
            if b.is_some_and(|b| b >= bricks) {
                *b = None;
            }
        }
        self.slot_of.resize(bricks, None);
        self.last_used.resize(bricks, 0);
    }

    /// Starts a frame or a streamed pass: bricks used from now on are the current ones.
    pub fn tick(&mut self) {
        self.clock += 1;
    }

    /// Makes `bricks` resident (at most `max_slots` of them): each is marked used now; those
    /// not resident take free slots, then the slots of evicted bricks; the pool grows (by
    /// whole layers of `layer` slots, up to `max_slots`) only when `bricks` exceed it. Evicted first: bricks no later pass of
    /// this frame needs (`later` gives [`NOT_LATER`]), least recently used first; then those
    /// a later pass needs, the last needed (largest `later`) first. Bricks used since the
    /// last [`Slots::tick`] stay. Returns the bricks to upload with their slots (the pool
    /// has [`Slots::allocated`] slots afterwards).
    pub fn place(
        &mut self,
        bricks: &[usize],
        later: impl Fn(usize) -> u32,
        layer: u32,
        max_slots: u32,
    ) -> Vec<(usize, u32)> {
        for &b in bricks {
            self.last_used[b] = self.clock;
        }
        let new: Vec<usize> = bricks
            .iter()
            .copied()
            .filter(|&b| self.slot_of[b].is_none())
            .collect();
        if bricks.len() as u32 > self.allocated() {
            let want = (bricks.len() as u32).div_ceil(layer) * layer;
            self.brick_in.resize(want.min(max_slots) as usize, None);
        }
        let mut free: Vec<u32> = (0..self.allocated())
            .filter(|&s| self.brick_in[s as usize].is_none())
            .collect();
        if new.len() > free.len() {
            let mut victims: Vec<(bool, u64, usize)> = self
                .brick_in
                .iter()
                .flatten()
                .copied()
                .filter(|&b| self.last_used[b] != self.clock)
                .map(|b| match later(b) {
                    NOT_LATER => (false, self.last_used[b], b),
                    l => (true, u64::MAX - l as u64, b),
                })
                .collect();
            victims.sort_unstable();
            for &(_, _, b) in victims.iter().take(new.len() - free.len()) {
                let s = self.slot_of[b].take().expect("a resident brick");
                self.brick_in[s as usize] = None;
                free.push(s);
            }
            free.sort_unstable();
        }
        debug_assert!(free.len() >= new.len(), "at most max_slots bricks at once");
        new.into_iter()
            .zip(free)
            .map(|(b, s)| {
                self.slot_of[b] = Some(s);
                self.brick_in[s as usize] = Some(b);
                (b, s)
            })
            .collect()
    }

    /// Shrinks the pool to `slots` slots: the bricks `needed` names stay first, then the most
    /// recently used, the rest are evicted. Returns the moves of the bricks that stay,
    /// (from slot, to slot), in slot order from 0.
    pub fn shrink(&mut self, slots: u32, needed: &[bool]) -> Vec<(u32, u32)> {
        let mut keep: Vec<(bool, u64, usize)> = self
            .brick_in
            .iter()
            .flatten()
            .map(|&b| (!needed[b], u64::MAX - self.last_used[b], b))
            .collect();
        keep.sort_unstable();
        keep.truncate(slots as usize);
        let moves = keep
            .iter()
            .enumerate()
            .map(|(to, &(_, _, b))| (self.slot_of[b].expect("resident"), to as u32))
            .collect();
        self.slot_of.fill(None);
        self.brick_in = vec![None; slots as usize];
        for (to, &(_, _, b)) in keep.iter().enumerate() {
            self.slot_of[b] = Some(to as u32);
            self.brick_in[to] = Some(b);
        }
        moves
    }
}

/// The bricks a ray may cross before brick `i`, one step away: implemented by the visibility
/// order (`BrickGrid::front_to_back`). Every brick a ray crosses before `i` is reached from
/// `i` by such steps.
pub(crate) trait Before {
    fn before(&self, i: usize) -> [Option<usize>; 3];
}

/// Splits the `needed` bricks into passes of at most `capacity` bricks for a streamed frame.
/// `order` lists every brick front to back (each brick after those [`Before`] names).
///
/// A brick joins a pass once every brick before it (by [`Before`], closed under repetition)
/// is in an earlier pass or this one; bricks not needed join free. So along any ray the
/// passes of the bricks it crosses never decrease: a ray marches the bricks of pass g in its
/// own order and stops at the first it needs from a later pass, never at one a pass already
/// evicted. Within that rule each pass takes resident bricks first (`slots`, replayed here
/// as the passes will place bricks: the caller passes a copy), then the rest front to back.
/// A pass always moves on: the first needed brick left in `order` has every brick before it
/// in earlier passes.
pub(crate) fn passes(
    order: &[usize],
    before: &impl Before,
    needed: &[bool],
    capacity: u32,
    mut slots: Slots,
    layer: u32,
) -> Vec<Vec<usize>> {
    let n = needed.len();
    let mut rank = vec![0u32; n];
    for (r, &b) in order.iter().enumerate() {
        rank[b] = r as u32;
    }
    let mut done = vec![false; n];
    let mut left = needed.iter().filter(|&&x| x).count();
    let mut passes = Vec::new();
    while left > 0 {
        let mut current = vec![false; n];
        let mut pass = Vec::new();
        for resident_only in [true, false] {
            for &b in order {
                if done[b] || current[b] {
                    continue;
                }
                let ready = before
                    .before(b)
                    .iter()
                    .flatten()
                    .all(|&p| done[p] || current[p]);
                if !ready {
                    continue;
                }
                if needed[b] {
                    if pass.len() as u32 == capacity
                        || (resident_only && slots.slot_of(b).is_none())
                    {
                        continue;
                    }
                    pass.push(b);
                }
                current[b] = true;
            }
        }
        for (d, c) in done.iter_mut().zip(&current) {
            *d |= c;
        }
        left -= pass.len();
        slots.tick();
        slots.place(
            &pass,
            |b| {
                if needed[b] && !done[b] {
                    rank[b]
                } else {
                    NOT_LATER
                }
            },
            layer,
            capacity,
        );
        passes.push(pass);
    }
    passes
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A row of bricks seen from its left end: each after its left neighbour.
    struct Row;
    impl Before for Row {
        fn before(&self, i: usize) -> [Option<usize>; 3] {
            [i.checked_sub(1), None, None]
        }
    }

    #[test]
    fn least_recently_used_out_first() {
        let mut s = Slots::new(6);
        s.tick();
        let placed = s.place(&[0, 1, 2, 3], |_| NOT_LATER, 2, 4);
        assert_eq!(placed, [(0, 0), (1, 1), (2, 2), (3, 3)]);
        s.tick();
        // 1 used again: 0, 2 and 3 were used before it, 0 first
        assert!(s.place(&[1], |_| NOT_LATER, 2, 4).is_empty());
        s.tick();
        assert_eq!(s.place(&[4], |_| NOT_LATER, 2, 4), [(4, 0)]);
        // a brick a later pass needs (2) goes after those none needs (3 is the oldest)
        s.tick();
        assert_eq!(
            s.place(&[5], |b| if b == 2 { 1 } else { NOT_LATER }, 2, 4),
            [(5, 3)]
        );
        // the pool grows only when the bricks asked for exceed it
        assert_eq!(s.allocated(), 4);
        assert_eq!((0..6).filter(|&b| s.slot_of(b).is_some()).count(), 4);
        // shrinking keeps the needed bricks, then the most recently used
        let moves = s.shrink(2, &[false, false, true, false, false, false]);
        assert_eq!(moves, [(2, 0), (3, 1)]);
        assert_eq!(
            (s.slot_of(2), s.slot_of(5), s.slot_of(1)),
            (Some(0), Some(1), None)
        );
    }

    #[test]
    fn passes_take_resident_bricks_first_in_order() {
        // eight bricks in a row, a pool of three; bricks 0 and 5 resident
        let mut s = Slots::new(8);
        s.tick();
        s.place(&[0, 5], |_| NOT_LATER, 1, 3);
        let order: Vec<usize> = (0..8).collect();
        let needed = [true, true, true, true, false, true, true, true];
        let p = passes(&order, &Row, &needed, 3, s.clone(), 1);
        // 5 cannot come before 1…3; the passes follow the row
        assert_eq!(p, [vec![0, 1, 2], vec![3, 5, 6], vec![7]]);
        // nothing resident: groups of three front to back
        let p = passes(&order, &Row, &needed, 3, Slots::new(8), 1);
        assert_eq!(p, [vec![0, 1, 2], vec![3, 5, 6], vec![7]]);
    }

    /// Two rows side by side (bricks 0–3 and 4–7): no ray crosses both.
    struct Rows;
    impl Before for Rows {
        fn before(&self, i: usize) -> [Option<usize>; 3] {
            [(!i.is_multiple_of(4)).then(|| i - 1), None, None]
        }
    }

    #[test]
    fn a_resident_row_goes_first() {
        let mut s = Slots::new(8);
        s.tick();
        s.place(&[4, 5, 6, 7], |_| NOT_LATER, 4, 4);
        let order = [0, 4, 1, 5, 2, 6, 3, 7];
        let needed = [true; 8];
        let p = passes(&order, &Rows, &needed, 4, s, 4);
        assert_eq!(p, [vec![4, 5, 6, 7], vec![0, 1, 2, 3]]);
    }
}

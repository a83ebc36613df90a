//! The one-ray walks' traversal stack ([`Stack`], never cleared) and [`pop`], which takes
//! the nearest pending child that may still hold a closer hit.

use crate::layout::MEDIAN_DEPTH;
use crate::simd::order::Pending;

pub(crate) const STACK: usize = 7 * (MEDIAN_DEPTH + 34) + 8;

/// A traversal stack that is not cleared before use (clearing a few kilobytes per ray
/// costs more than a small BVH's whole traversal). Entries are written before they are read:
/// `get(i)` is only called for `i` below the highest index pushed.
pub(crate) struct Stack<T: Copy> {
    pub(crate) items: [std::mem::MaybeUninit<T>; STACK],
}

impl<T: Copy> Stack<T> {
    #[inline(always)]
    pub(crate) fn new() -> Stack<T> {
        Stack {
            items: [const { std::mem::MaybeUninit::uninit() }; STACK],
        }
    }

    #[inline(always)]
    pub(crate) fn push(&mut self, i: usize, v: T) {
        self.items[i] = std::mem::MaybeUninit::new(v);
    }

    /// Slots `i..i + 8`, to be written at once. A walk's stack holds at most seven
    /// children per level above the node it is at, so past the deepest node's pushes it
    /// has room for these eight ([`STACK`]).
    #[inline(always)]
    pub(crate) fn eight(&mut self, i: usize) -> &mut [std::mem::MaybeUninit<T>; 8] {
        (&mut self.items[i..i + 8]).try_into().expect("eight slots")
    }

    #[inline(always)]
    pub(crate) fn get(&self, i: usize) -> T {
        debug_assert!(i < STACK);
        // SAFETY: the traversals read slot i only after pushing it (the stack pointer never
        // passes the highest slot written), so it lies in the stack (`push` and `eight`
        // check their slots) and holds an initialized value.
        unsafe { self.items.get_unchecked(i).assume_init() }
    }
}

/// Pops the nearest pending child that may still hold a closer hit (one entered no farther
/// than `reach`), dropping those that cannot.
#[inline(always)]
pub(crate) fn pop(stack: &Stack<Pending>, sp: &mut usize, reach: f32) -> Option<u32> {
    while *sp > 0 {
        *sp -= 1;
        let p = stack.get(*sp);
        if p.t_near <= reach {
            return Some(p.node);
        }
    }
    None
}

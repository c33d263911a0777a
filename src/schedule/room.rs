//! Short-lived lists of a known greatest length for the scheduler's fast paths: on the stack when
//! they are short, with their length kept by the caller.
//!
//! A `SmallVec` created and filled at once was slower here than its instruction count says: in a
//! time profile of `Optimal` on a one-behaviour block, its first read of its own capacity after
//! `SmallVec::new()` was among the hottest instructions (about 2.4 % of the scheduler's samples for
//! each such list). A plain array does not read anything back.

/// `n` items set to `T::default()`: in `stack` when it is long enough, else in `heap` (resized).
pub(crate) fn room<'a, T: Copy + Default, const N: usize>(
    n: usize,
    stack: &'a mut [T; N],
    heap: &'a mut Vec<T>,
) -> &'a mut [T] {
    if n <= N {
        let s = &mut stack[..n];
        s.fill(T::default());
        s
    } else {
        heap.clear();
        heap.resize(n, T::default());
        heap
    }
}

#[cfg(test)]
mod tests {
    use super::room;

    #[test]
    fn room_is_on_the_stack_when_short_and_always_cleared() {
        let (mut stack, mut heap) = ([7u32; 4], Vec::new());
        let r = room(3, &mut stack, &mut heap);
        assert_eq!(r, [0, 0, 0]);
        r[0] = 5;
        assert_eq!(stack[0], 5, "three items fit on the stack");
        let r = room(6, &mut stack, &mut heap);
        assert_eq!(r, [0; 6]);
        assert_eq!(heap.len(), 6, "six do not");
    }
}

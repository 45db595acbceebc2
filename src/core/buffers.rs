//! Reusable buffers that a step fills: sized when the engine learns what it holds (chains, colliders,
//! settings), so that no step allocates however its work changes from one step to the next.

/// Capacity for `total` elements in all, counted from zero: `Vec::reserve` counts from the current length,
/// and a reused buffer keeps the length of its last use.
pub(crate) fn reserve_total<T>(v: &mut Vec<T>, total: usize) {
    v.reserve(total.saturating_sub(v.len()));
}

#[cfg(test)]
mod tests {
    use super::reserve_total;

    #[test]
    fn room_is_counted_from_zero_whatever_the_length() {
        let mut v = vec![0u8; 10];
        let capacity = v.capacity();
        reserve_total(&mut v, 10);
        assert_eq!(v.capacity(), capacity, "a full buffer of 10 has room for 10");
        v.clear();
        reserve_total(&mut v, 10);
        assert_eq!(v.capacity(), capacity);
        reserve_total(&mut v, 25);
        assert!(v.capacity() >= 25);
    }
}

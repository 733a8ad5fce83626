//! Values grouped by a small integer key in O(n): a counting sort into the
//! compressed layout (CSR) the topology passes share: the edges at a
//! vertex (`topology`, the boundary and the sweep's owners) and a boundary
//! vertex's edges (`fiducials`).

/// Values grouped by key: group `k` is `items[start[k]..start[k + 1]]`,
/// its values in the order they came.
pub(crate) struct Buckets {
    pub start: Vec<u32>,
    pub items: Vec<u32>,
}

impl Buckets {
    /// Groups the `(key, value)` pairs, keys below `keys`. `pairs` is
    /// called twice, to count and then to place, and must give the same
    /// pairs both times.
    pub fn new<I: Iterator<Item = (u32, u32)>>(keys: usize, pairs: impl Fn() -> I) -> Buckets {
        Buckets::group(keys, |emit| pairs().for_each(|(k, v)| emit(k, v)))
    }

    /// [`Self::new`] for pairs that come from loops of their own: `each`
    /// hands every pair to the function it is given, twice, the same
    /// pairs in the same order (plain loops beat an iterator of arrays'
    /// pairs by a tenth on the topology's 6 M edges). The groups' starts
    /// serve as their cursors while placing (no second array of `keys`
    /// counters).
    #[inline]
    pub fn group(keys: usize, each: impl Fn(&mut dyn FnMut(u32, u32))) -> Buckets {
        let mut start = vec![0u32; keys + 1];
        each(&mut |k, _| start[k as usize + 1] += 1);
        for k in 0..keys {
            start[k + 1] += start[k];
        }
        let mut items = vec![0u32; start[keys] as usize];
        each(&mut |k, v| {
            let cursor = &mut start[k as usize];
            items[*cursor as usize] = v;
            *cursor += 1;
        });
        // Each cursor now stands at its group's end, the next one's start.
        start.copy_within(0..keys, 1);
        start[0] = 0;
        Buckets { start, items }
    }

    /// Group `k`.
    #[inline]
    pub fn get(&self, k: u32) -> &[u32] {
        &self.items[self.start[k as usize] as usize..self.start[k as usize + 1] as usize]
    }
}

#[cfg(test)]
mod tests {
    use super::Buckets;

    #[test]
    fn groups_keep_their_values_in_order_and_empty_keys_stay_empty() {
        let pairs = [(2, 10), (0, 11), (2, 12), (4, 13), (2, 14), (0, 15)];
        let b = Buckets::new(5, || pairs.iter().copied());
        assert_eq!(b.get(0), &[11, 15]);
        assert_eq!(b.get(1), &[] as &[u32]);
        assert_eq!(b.get(2), &[10, 12, 14]);
        assert_eq!(b.get(3), &[] as &[u32]);
        assert_eq!(b.get(4), &[13]);
        assert_eq!(b.start, vec![0, 2, 2, 5, 5, 6]);
        let none = Buckets::new(3, std::iter::empty);
        assert_eq!(none.start, vec![0; 4]);
    }
}

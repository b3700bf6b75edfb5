//! Pairing of two lists by a key, and detection of reordered elements.

/// One element of the pairing of an old and a new list.
#[derive(Debug)]
pub enum Pair<'a, T> {
    /// In both lists (old index, old, new index, new).
    Both(usize, &'a T, usize, &'a T),
    /// Only in the old list.
    Old(&'a T),
    /// Only in the new list.
    New(&'a T),
}

/// Pairs the k-th occurrence of a key in `old` with its k-th occurrence in `new`. The
/// result follows the new order; an element only in `old` comes right after the element
/// that precedes it in `old` and is kept in both.
pub fn pair<'a, T, K: PartialEq>(
    old: &'a [T],
    new: &'a [T],
    key: impl Fn(&T) -> K,
) -> Vec<Pair<'a, T>> {
    let old_keys: Vec<K> = old.iter().map(&key).collect();
    let new_keys: Vec<K> = new.iter().map(&key).collect();
    let mut old_used = vec![false; old.len()];
    let mut partner_of_old: Vec<Option<usize>> = vec![None; old.len()];
    let mut partner_of_new: Vec<Option<usize>> = vec![None; new.len()];
    for (j, k) in new_keys.iter().enumerate() {
        if let Some(i) = (0..old.len()).find(|&i| !old_used[i] && old_keys[i] == *k) {
            old_used[i] = true;
            partner_of_old[i] = Some(j);
            partner_of_new[j] = Some(i);
        }
    }
    // Sort key: (position in the new list, 0 for the new element / 1.. for removed ones).
    let mut placed: Vec<((usize, usize), Pair<'a, T>)> = Vec::with_capacity(old.len() + new.len());
    for (j, n) in new.iter().enumerate() {
        let p = match partner_of_new[j] {
            Some(i) => Pair::Both(i, &old[i], j, n),
            None => Pair::New(n),
        };
        placed.push(((j + 1, 0), p));
    }
    for (i, o) in old.iter().enumerate() {
        if partner_of_old[i].is_some() {
            continue;
        }
        let anchor = (0..i)
            .rev()
            .find_map(|p| partner_of_old[p])
            .map_or(0, |j| j + 1);
        placed.push(((anchor, i + 1), Pair::Old(o)));
    }
    placed.sort_by_key(|(k, _)| *k);
    placed.into_iter().map(|(_, p)| p).collect()
}

/// For each element present in both lists (in new order), whether it moved relative to
/// the others.
pub fn moved_pairs<T>(pairs: &[Pair<'_, T>]) -> Vec<bool> {
    let olds: Vec<usize> = pairs
        .iter()
        .filter_map(|p| match p {
            Pair::Both(i, ..) => Some(*i),
            _ => None,
        })
        .collect();
    moved(&olds)
}

/// Among paired elements, the old indices (in new order) that are not in a longest
/// increasing subsequence: the elements that moved relative to the others.
pub fn moved(old_indices_in_new_order: &[usize]) -> Vec<bool> {
    let a = old_indices_in_new_order;
    let n = a.len();
    // O(n^2) longest increasing subsequence: lists here are short (steps, attitudes).
    let mut len = vec![1usize; n];
    let mut prev = vec![usize::MAX; n];
    for j in 0..n {
        for i in 0..j {
            if a[i] < a[j] && len[i] + 1 > len[j] {
                len[j] = len[i] + 1;
                prev[j] = i;
            }
        }
    }
    let mut in_lis = vec![false; n];
    if let Some(mut k) = (0..n).max_by_key(|&k| (len[k], std::cmp::Reverse(k))) {
        loop {
            in_lis[k] = true;
            if prev[k] == usize::MAX {
                break;
            }
            k = prev[k];
        }
    }
    in_lis.into_iter().map(|b| !b).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn show(p: &[Pair<'_, char>]) -> String {
        p.iter()
            .map(|p| match p {
                Pair::Both(_, o, _, _) => format!("={o}"),
                Pair::Old(o) => format!("-{o}"),
                Pair::New(n) => format!("+{n}"),
            })
            .collect::<Vec<_>>()
            .join(" ")
    }

    #[test]
    fn removed_elements_stay_near_their_neighbours() {
        let old = ['a', 'b', 'c', 'd'];
        let new = ['a', 'c', 'x', 'd'];
        assert_eq!(show(&pair(&old, &new, |c| *c)), "=a -b =c +x =d");
        let old = ['q', 'a'];
        let new = ['a'];
        assert_eq!(show(&pair(&old, &new, |c| *c)), "-q =a");
    }

    #[test]
    fn repeated_keys_pair_in_order() {
        let old = ['a', 'a', 'b'];
        let new = ['a', 'b'];
        assert_eq!(show(&pair(&old, &new, |c| *c)), "=a -a =b");
    }

    #[test]
    fn one_moved_element_is_found() {
        // old order a b c d; new order b c a d: only `a` moved
        assert_eq!(moved(&[1, 2, 0, 3]), vec![false, false, true, false]);
        assert_eq!(moved(&[0, 1, 2]), vec![false; 3]);
        assert!(moved(&[]).is_empty());
        // a swap: one of the two is reported
        assert_eq!(moved(&[1, 0]).iter().filter(|m| **m).count(), 1);
    }
}

//! Strongly connected components of a topic type's dependency graph (XTypes 1.3 §7.3.4.9), found the way
//! Cyclone DDS 11's Python binding finds them (Kosaraju's algorithm over the types that have dependencies,
//! components numbered by their root), so that the dependency lists built from them come in its order.

/// The components of the nodes `inner` of a graph given by `edges` (node indexes; edges to nodes outside
/// `inner` are ignored).
pub(crate) struct Components {
    /// The nodes of each component, in node order.
    pub(crate) members: Vec<Vec<usize>>,
    /// The other components each one depends on, ascending.
    pub(crate) deps: Vec<Vec<usize>>,
    /// Whether each component is recursive: more than one type, or one that depends on itself.
    pub(crate) recursive: Vec<bool>,
}

impl Components {
    /// Finds the components. The component of `inner[0]` is component 0.
    pub(crate) fn find(edges: &[Vec<usize>], inner: &[usize]) -> Self {
        let n = edges.len();
        let in_inner = {
            let mut v = vec![false; n];
            inner.iter().for_each(|&i| v[i] = true);
            v
        };
        let in_inner = &in_inner;
        let out = |u: usize| edges[u].iter().copied().filter(move |&v| in_inner[v]);
        // 1–2: post-order of a depth-first search from each node in order; the reverse graph on the way.
        let mut visited = vec![false; n];
        let mut order = Vec::with_capacity(inner.len());
        let mut reverse: Vec<Vec<usize>> = vec![Vec::new(); n];
        for &u in inner {
            visit(u, &out, &mut visited, &mut order, &mut reverse);
        }
        // 3: assign each node, latest finished first, to the root it is reached from in the reverse graph.
        let mut root = vec![usize::MAX; n];
        for &u in order.iter().rev() {
            if root[u] == usize::MAX {
                assign(u, u, &reverse, &mut root);
            }
        }
        let mut roots: Vec<usize> = inner.iter().map(|&u| root[u]).collect();
        roots.sort_unstable();
        roots.dedup();
        let mut of = vec![None; n];
        let mut members = vec![Vec::new(); roots.len()];
        for &u in inner {
            let c = roots.binary_search(&root[u]).unwrap_or(0);
            of[u] = Some(c);
            members[c].push(u);
        }
        let mut deps = vec![Vec::new(); roots.len()];
        let mut recursive = vec![false; roots.len()];
        for &u in inner {
            let c = of[u].unwrap_or(0);
            recursive[c] |= members[c].len() > 1;
            for v in out(u) {
                match of[v] {
                    Some(d) if d == c => recursive[c] |= v == u,
                    Some(d) => deps[c].push(d),
                    None => {}
                }
            }
        }
        for d in &mut deps {
            d.sort_unstable();
            d.dedup();
        }
        Components {
            members,
            deps,
            recursive,
        }
    }

    /// The components `c` depends on, directly or not, then `c`: depth first, dependencies in ascending
    /// order, repeats kept (the binding's `_handle_component`).
    pub(crate) fn post_order(&self, c: usize, out: &mut Vec<usize>) {
        for &d in &self.deps[c] {
            self.post_order(d, out);
        }
        out.push(c);
    }
}

fn visit<I: Iterator<Item = usize>>(
    u: usize,
    out: &impl Fn(usize) -> I,
    visited: &mut [bool],
    order: &mut Vec<usize>,
    reverse: &mut [Vec<usize>],
) {
    if visited[u] {
        return;
    }
    visited[u] = true;
    for v in out(u) {
        visit(v, out, visited, order, reverse);
        reverse[v].push(u);
    }
    order.push(u);
}

fn assign(u: usize, r: usize, reverse: &[Vec<usize>], root: &mut [usize]) {
    if root[u] != usize::MAX {
        return;
    }
    root[u] = r;
    for &v in &reverse[u] {
        assign(v, r, reverse, root);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    impl Components {
        fn of(&self, node: usize) -> Option<usize> {
            self.members.iter().position(|m| m.contains(&node))
        }
    }

    #[test]
    fn cycles_self_loops_and_plain_dependencies() {
        // 0 -> {1, 2}; 1 -> 1; 2 <-> 3; 4 is a leaf (not inner).
        let edges = vec![vec![2, 1, 4], vec![1], vec![3], vec![2, 4], vec![]];
        let c = Components::find(&edges, &[0, 1, 2, 3]);
        assert_eq!(c.of(0), Some(0));
        assert_eq!(c.of(4), None);
        assert_eq!(c.of(2), c.of(3));
        let (one, two) = (c.of(1).unwrap(), c.of(2).unwrap());
        assert_eq!(c.members[two], [2, 3]);
        assert_eq!(c.recursive, {
            let mut r = vec![false; 3];
            r[one] = true;
            r[two] = true;
            r
        });
        let mut post = Vec::new();
        c.post_order(0, &mut post);
        assert_eq!(post.last(), Some(&0));
        assert_eq!(post.len(), 3);
    }
}

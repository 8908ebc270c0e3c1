//! The recursive types of `scripts/golden/rec_golden` as derived types, shared by the recursive-type tests.

use dds_runtime::DdsType;

/// `@final struct Node { long value; sequence<Node> children; };`
#[derive(DdsType, Debug, Clone, PartialEq, Default)]
#[dds(name = "Rec::Node", final)]
pub struct Node {
    pub value: i32,
    #[dds(recursive)]
    pub children: Vec<Node>,
}

/// `@final struct A { long x; sequence<B> bs; };`
#[derive(DdsType, Debug, Clone, PartialEq, Default)]
#[dds(name = "Rec::A", final)]
pub struct A {
    pub x: i32,
    #[dds(recursive)]
    pub bs: Vec<B>,
}

/// `@final struct B { long y; sequence<A> as_; };`
#[derive(DdsType, Debug, Clone, PartialEq, Default)]
#[dds(name = "Rec::B", final)]
pub struct B {
    pub y: i32,
    pub as_: Vec<A>,
}

/// `@final struct Leaf { string name; };`
#[derive(DdsType, Debug, Clone, PartialEq, Default)]
#[dds(name = "Rec::Leaf", final)]
pub struct Leaf {
    pub name: String,
}

/// `@appendable struct Tree { long v; Leaf leaf; sequence<Tree, 4> kids; };`
#[derive(DdsType, Debug, Clone, PartialEq, Default)]
#[dds(name = "Rec::Tree", appendable)]
pub struct Tree {
    pub v: i32,
    pub leaf: Leaf,
    #[dds(recursive, bound = 4)]
    pub kids: Vec<Tree>,
}

/// `@final struct Holder { @key long id; Node root; A a; };`
#[derive(DdsType, Debug, Clone, PartialEq, Default)]
#[dds(name = "Rec::Holder", final)]
pub struct Holder {
    #[dds(key)]
    pub id: i32,
    pub root: Node,
    pub a: A,
}

/// `@mutable struct Chain { long v; @optional Chain next; };`
#[derive(DdsType, Debug, Clone, PartialEq, Default)]
#[dds(name = "Rec::Chain", mutable)]
pub struct Chain {
    pub v: i32,
    #[dds(recursive)]
    pub next: Option<Box<Chain>>,
}

/// The `Node` value the golden script serializes and the tests write: `1 [2, 3 [4]]`.
pub fn node_value() -> Node {
    let leaf = |value| Node {
        value,
        children: vec![],
    };
    Node {
        value: 1,
        children: vec![
            leaf(2),
            Node {
                value: 3,
                children: vec![leaf(4)],
            },
        ],
    }
}

/// A `Node` nested `depth` deep, XCDR1 little endian, written by hand (not by our encoder, which refuses to
/// write past the depth limit): each level is `value` and a one-element `children`, the last an empty one.
pub fn nested_node_bytes(depth: usize) -> Vec<u8> {
    let mut b = vec![0x00, 0x01, 0x00, 0x00];
    for i in 0..depth {
        b.extend((i as i32).to_le_bytes());
        b.extend(1u32.to_le_bytes());
    }
    b.extend(0i32.to_le_bytes());
    b.extend(0u32.to_le_bytes());
    b
}

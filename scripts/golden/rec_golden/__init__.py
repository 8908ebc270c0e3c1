"""Recursive types for recursive_typeinfo.py, as Python classes of Cyclone DDS 11.0.1's binding. They live in a
package of their own because the binding resolves forward references ('rec_golden.Node') by importing the
module named in them. Each type's IDL is in its docstring (module Rec)."""
from dataclasses import dataclass
from typing import Optional

import cyclonedds.idl as idl
import cyclonedds.idl.annotations as annotate
import cyclonedds.idl.types as types


@dataclass
@annotate.final
class Node(idl.IdlStruct, typename="Rec::Node"):
    """@final struct Node { long value; sequence<Node> children; };"""
    value: types.int32
    children: types.sequence['rec_golden.Node']


@dataclass
@annotate.final
class A(idl.IdlStruct, typename="Rec::A"):
    """@final struct A { long x; sequence<B> bs; };"""
    x: types.int32
    bs: types.sequence['rec_golden.B']


@dataclass
@annotate.final
class B(idl.IdlStruct, typename="Rec::B"):
    """@final struct B { long y; sequence<A> as_; };"""
    y: types.int32
    as_: types.sequence['rec_golden.A']


@dataclass
@annotate.final
class Leaf(idl.IdlStruct, typename="Rec::Leaf"):
    """@final struct Leaf { string name; };"""
    name: str


@dataclass
@annotate.appendable
class Tree(idl.IdlStruct, typename="Rec::Tree"):
    """@appendable struct Tree { long v; Leaf leaf; sequence<Tree, 4> kids; };"""
    v: types.int32
    leaf: Leaf
    kids: types.sequence['rec_golden.Tree', 4]


@dataclass
@annotate.final
class Holder(idl.IdlStruct, typename="Rec::Holder"):
    """@final struct Holder { @key long id; Node root; A a; };"""
    id: types.int32
    annotate.key("id")
    root: Node
    a: A


@dataclass
@annotate.mutable
class Chain(idl.IdlStruct, typename="Rec::Chain"):
    """@mutable struct Chain { long v; @optional Chain next; };"""
    v: types.int32
    next: Optional['rec_golden.Chain']

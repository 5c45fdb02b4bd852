#!/usr/bin/env python3
"""Checks a .feb file written by `voxbreast export --feb`: valid against the FEBio spec 4.0 schema
(tests/io/febio_spec_4.xsd, lxml), node and element ids numbered 1..n, every corner a node, every
hex8 of positive volume with edges of one lattice spacing, and the fixed node set made of nodes.
Prints the counts; exits non-zero naming the first problem.
    python3 tests/io/check_febio.py model.feb [--spacing H]"""
import argparse
import os
import sys

import numpy as np
from lxml import etree

parser = argparse.ArgumentParser()
parser.add_argument("feb")
parser.add_argument("--spacing", type=float, help="lattice spacing (m) every hex edge must have")
args = parser.parse_args()

schema = etree.XMLSchema(etree.parse(os.path.join(os.path.dirname(os.path.abspath(__file__)), "febio_spec_4.xsd")))
doc = etree.parse(args.feb)
if not schema.validate(doc):
    sys.exit(f"{args.feb}: not valid FEBio 4.0: {schema.error_log.last_error}")
spec = doc.getroot()


def ids(elements):
    return [int(e.get("id")) for e in elements]


nodes = spec.findall("Mesh/Nodes/node")
if ids(nodes) != list(range(1, len(nodes) + 1)):
    sys.exit("node ids are not 1..n in order")
x = np.array([[float(v) for v in n.text.split(",")] for n in nodes])
elems = spec.findall("Mesh/Elements/elem")
if ids(elems) != list(range(1, len(elems) + 1)):
    sys.exit("element ids are not 1..n in order")
hexes = np.array([[int(v) for v in e.text.split(",")] for e in elems]) - 1
if hexes.min() < 0 or hexes.max() >= len(nodes):
    sys.exit("an element names a node that does not exist")
if len(np.unique(hexes)) != len(nodes):
    sys.exit("some node is a corner of no element")
c = x[hexes]  # hexes × 8 corners × 3
volume = np.einsum("ij,ij->i", np.cross(c[:, 1] - c[:, 0], c[:, 3] - c[:, 0]), c[:, 4] - c[:, 0])
if (volume <= 0).any():
    sys.exit(f"{int((volume <= 0).sum())} elements have a negative corner volume")
if args.spacing:
    edges = np.concatenate([np.linalg.norm(c[:, b] - c[:, a], axis=1)
                            for a, b in [(0, 1), (1, 2), (2, 3), (3, 0), (0, 4), (4, 5), (5, 6), (6, 7), (7, 4)]])
    if np.abs(edges - args.spacing).max() > 1e-9 * args.spacing + 1e-12:
        sys.exit(f"an edge is not one lattice spacing ({edges.min()}..{edges.max()} m)")
fixed = spec.find("Mesh/NodeSet")
n_fixed = 0
if fixed is not None:
    held = [int(v) for v in fixed.text.split(",")]
    if min(held) < 1 or max(held) > len(nodes) or len(set(held)) != len(held):
        sys.exit("the fixed node set names nodes that do not exist, or twice")
    n_fixed = len(held)
print(f"{args.feb}: valid FEBio 4.0, {len(nodes)} nodes, {len(elems)} hex8, {n_fixed} fixed, "
      f"{len(spec.findall('Material/material'))} materials")

#!/usr/bin/env python3
"""Open MPI rankfile for basalt-run with one I/O rank per node (docs/io-ranks.md, "Several nodes").

basalt-run: world ranks 0..P-1 compute, P..P+Q-1 are I/O ranks; compute rank c is served by I/O rank
P + (c mod Q) (iolayer/ioranks/src/rank_layout.cpp). With Q = number of nodes N and P = N*C:

  --placement io-local: compute rank c on node c mod N, I/O rank P + j on node j. Every compute rank's
      I/O rank is on its own node (frames never cross the network); grid neighbours mostly do not share a node.
  --placement block:    compute ranks c*C .. c*C+C-1 on node c (grid neighbours share nodes), I/O rank P + j
      on node j; compute rank c is then served by an I/O rank on node c mod N, on its own node only for
      a fraction 1/N of the ranks.

  make_rankfile.py --compute-per-node 32 node01 node02 node03 node04 > rankfile
  mpirun -np 132 --rankfile rankfile basalt-run scene.toml --io-ranks 4 ...
"""
import argparse

ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
ap.add_argument("hosts", nargs="+", help="node names, one I/O rank each")
ap.add_argument("--compute-per-node", type=int, required=True)
ap.add_argument("--placement", choices=["io-local", "block"], default="io-local")
a = ap.parse_args()
n, c = len(a.hosts), a.compute_per_node
if c < 1:
    ap.error("--compute-per-node must be >= 1")
p = n * c
slot = {h: 0 for h in a.hosts}


def place(rank, host):
    print(f"rank {rank}={host} slot={slot[host]}")
    slot[host] += 1


for r in range(p):
    place(r, a.hosts[r % n] if a.placement == "io-local" else a.hosts[r // c])
for j in range(n):
    place(p + j, a.hosts[j])

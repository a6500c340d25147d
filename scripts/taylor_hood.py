#!/usr/bin/env python3
"""An independent solution for the mixed formulation (issue #62): the bending beam in linear
elasticity with Taylor–Hood tetrahedra (P2 displacement, continuous P1 pressure) in scikit-fem,
a finite-element code that shares nothing with hox.

    python3 scripts/taylor_hood.py [--cells 8,16,24,32] [--poisson 0.499] [--youngs 3e9] [--json]

The beam [0, 2] × [0, 0.5] × [0, 0.5] m clamped at x = 0 under gravity (ρ = 1000 kg/m³,
g = 9.81 m/s² along −z), as the bending scene, with E = 3 GPa by default: a tip sag of a third
of a millimetre, the linear regime, where hox's StVK static solution is linear elasticity's
(assets/scenes/bending.toml has E = 3 MPa). The displacement–pressure saddle point

    ∫ 2μ ε(u):ε(v) − ∫ p div v = ∫ ρ g · v,    −∫ q div u − ∫ p q / λ = 0

is solved for every mesh of N × N/4 × N/4 hexahedra cut into six tetrahedra each
(`MeshTet.init_tensor`), and the tip's z displacement at (2, 0.25, 0.25) printed, with
Richardson's limit of the last three meshes. Needs scikit-fem and scipy (pip); prints one line
per mesh, or with --json one JSON object.
"""
import argparse
import json
import math
import sys

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from skfem import Basis, BilinearForm, ElementTetP1, ElementTetP2, ElementVector, LinearForm, MeshTet, condense, solve
from skfem.helpers import ddot, div, sym_grad

LENGTH_M, WIDTH_M = 2.0, 0.5
RHO_KG_M3, G_M_S2 = 1000.0, 9.81


def tip_sag_m(cells: int, youngs_pa: float, nu: float) -> tuple[float, int]:
    lam = youngs_pa * nu / ((1 + nu) * (1 - 2 * nu))
    mu = youngs_pa / (2 * (1 + nu))
    across = cells // 4
    mesh = MeshTet.init_tensor(
        np.linspace(0, LENGTH_M, cells + 1), np.linspace(0, WIDTH_M, across + 1), np.linspace(0, WIDTH_M, across + 1)
    )
    ub = Basis(mesh, ElementVector(ElementTetP2()))
    pb = ub.with_element(ElementTetP1())

    @BilinearForm
    def stiffness(u, v, _):
        return 2 * mu * ddot(sym_grad(u), sym_grad(v))

    @BilinearForm
    def coupling(p, v, _):
        return -p * div(v)

    @BilinearForm
    def pressure_mass(p, q, _):
        return p * q / lam

    @LinearForm
    def weight(v, _):
        return -RHO_KG_M3 * G_M_S2 * v[2]

    a = stiffness.assemble(ub)
    b = coupling.assemble(pb, ub)
    c = pressure_mass.assemble(pb)
    system = sp.bmat([[a, b], [b.T, -c]], format="csr")
    rhs = np.concatenate([weight.assemble(ub), np.zeros(pb.N)])
    clamped = ub.get_dofs(lambda x: np.isclose(x[0], 0.0)).all()
    x = solve(*condense(system, rhs, D=clamped), solver=spla.spsolve)
    u = x[: ub.N]
    tip = np.array([LENGTH_M, WIDTH_M / 2, WIDTH_M / 2])
    vertex = int(np.argmin(np.linalg.norm(mesh.p.T - tip, axis=1)))
    assert np.allclose(mesh.p[:, vertex], tip), "the tip is a vertex of every mesh"
    return float(u[ub.nodal_dofs[2, vertex]]), int(system.shape[0])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cells", default="8,16,24,32", help="cells along the beam, each a multiple of 8")
    parser.add_argument("--poisson", type=float, default=0.499)
    parser.add_argument("--youngs", type=float, default=3e9)
    parser.add_argument("--json", action="store_true")
    args = parser.parse_args()
    cells = [int(c) for c in args.cells.split(",")]
    if any(c % 8 or c <= 0 for c in cells):
        sys.exit("taylor_hood: --cells must be positive multiples of 8 (the tip is then a vertex)")
    levels = []
    for n in cells:
        sag, dofs = tip_sag_m(n, args.youngs, args.poisson)
        levels.append({"cells": n, "dofs": dofs, "tip_z_m": sag})
        if not args.json:
            print(f"Taylor-Hood P2-P1, {n}x{n // 4}x{n // 4} x6 tets, {dofs} unknowns: tip z {sag:.6e} m", flush=True)
    limit = None
    if len(levels) >= 3:
        (h1, u1), (h2, u2), (h3, u3) = [(1.0 / l["cells"], l["tip_z_m"]) for l in levels[-3:]]
        # the order from the three levels (any ratios), then the limit from the two finest
        def gap(p: float) -> float:
            return (u1 - u2) / (u2 - u3) - (h1**p - h2**p) / (h2**p - h3**p)

        lo, hi = 0.5, 6.0
        if (u2 - u3) != 0 and gap(lo) * gap(hi) < 0:
            for _ in range(100):
                mid = 0.5 * (lo + hi)
                lo, hi = (mid, hi) if gap(lo) * gap(mid) > 0 else (lo, mid)
            p = 0.5 * (lo + hi)
            limit = {"order": p, "tip_z_m": u3 + (u3 - u2) * h3**p / (h2**p - h3**p)}
    if args.json:
        print(json.dumps({"poisson_ratio": args.poisson, "youngs_modulus_pa": args.youngs, "levels": levels, "limit": limit}))
    elif limit:
        print(f"Richardson limit (order {limit['order']:.2f}): tip z {limit['tip_z_m']:.6e} m")


if __name__ == "__main__":
    main()

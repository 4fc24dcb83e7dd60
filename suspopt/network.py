"""Lumped element networks: the one form the equations of motion of every model take.

A network has ``n`` degrees of freedom ``q`` (vertical displacements [m] and body rotations
[rad], measured from static equilibrium) and ``n_u`` inputs ``u`` (prescribed displacements: the
road under each wheel, or the floor under a seat). Its elements come in groups; the ``m``
elements of a group act along the deformations

    δ = D_q q + D_u u,        δ̇ = D_q q̇ + D_u u̇

and each carries the force ``F = k δ + c δ̇ + F_x(δ, δ̇)`` that resists its deformation
(``F_x`` the group's non-linear part: a Duffing term, tyre lift-off, a negative-stiffness
mechanism). By virtual work the group's generalised force is ``-D_qᵀ F`` on the DOFs and
``-D_uᵀ F`` on the inputs (the reaction on the road or the floor), so

    M q̈ = -Σ_groups D_qᵀ F.

The vehicle (:mod:`suspopt.vehicle`: suspension springs and dampers, tyres, anti-roll bars) and
the seat with its passenger (:mod:`suspopt.seat`: links, mechanism) are networks; a seat is
mounted by :meth:`Network.attach`, which replaces the seat's floor input by the body's motion
at the seat's point and, for a two-way (coupled) seat, puts the floor reaction on the body.
The simulator integrates the assembled network (:mod:`suspopt.simulate`), and the linear
analyses (modes, frequency responses, transmissibility) take its matrices from
:meth:`Network.linear_model`: one description of the physics serves both.

Layout: element and DOF arrays are ``(rows, P, S)`` - rows (DOFs or elements), P designs,
S samples (1 while integrating, T afterwards); parameters are ``(rows, P, 1)``; inputs
``(n_u, 1, S)``, the same for every design.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, replace

import numpy as np

__all__ = ["Elements", "Network", "LinearModel", "apply", "parameter_rows", "widen"]


def apply(matrix: np.ndarray, x: np.ndarray) -> np.ndarray:
    """``matrix @ x`` over the rows of ``x (c, P, S)``: ``matrix`` (r, c) for every design, or
    (P, r, c) per design. Returns (r, P, S)."""
    if matrix.ndim == 2:
        return (matrix @ x.reshape(x.shape[0], -1)).reshape(matrix.shape[0], *x.shape[1:])
    return np.einsum("prc,cps->rps", matrix, x)


def parameter_rows(values: np.ndarray) -> np.ndarray:
    """Per-design values ``(P, rows)`` (element parameters, DOF masses) in the network layout
    ``(rows, P, 1)``, contiguous."""
    return np.ascontiguousarray(values.T)[:, :, None]


def widen(a: np.ndarray, width: int) -> np.ndarray:
    """A parameter array ``(..., P, 1)`` (P = 1 or ``width``) as a contiguous ``(..., width,
    1)`` array: numpy combines equal shapes several times faster than it broadcasts."""
    if a.shape[-2] == width:
        return a
    return np.ascontiguousarray(np.broadcast_to(a, a.shape[:-2] + (width, 1)))


@dataclass
class Elements:
    """A group of ``m`` elements (see the module docstring).

    ``dof_map`` D_q (m, n), or (P, m, n) when it differs between designs; ``input_map`` D_u
    (m, n_u); ``stiffness`` k and ``damping`` c (m, P, 1) [N/m, N s/m; N m/rad for a torsional
    element]; ``extra`` the non-linear part or None: ``extra(width)`` returns the function
    ``(δ, δ̇, k δ + c δ̇, out)`` that writes F_x (m, width, S) [N] into ``out`` for ``width``
    design columns (its parameters widened to them, :func:`widen`), with ``extra_slope`` its
    derivative dF_x/dδ at rest (m, P, 1) [N/m] for the linearised model (None for 0) and
    ``extra_uses_force`` whether F_x reads its third argument; ``reacts`` (n,) bool marks the
    DOFs that feel the group's force (None: all - a one-way seat's links do not push the body).
    """

    name: str
    dof_map: np.ndarray
    input_map: np.ndarray
    stiffness: np.ndarray
    damping: np.ndarray
    extra: Callable[[int], Callable[..., object]] | None = None
    extra_slope: np.ndarray | None = None
    extra_uses_force: bool = False
    reacts: np.ndarray | None = None

    @property
    def size(self) -> int:
        return self.stiffness.shape[0]

    @property
    def force_map(self) -> np.ndarray:
        """Generalised force on the DOFs per unit element force, ``-D_qᵀ`` masked by
        ``reacts``: (n, m), or (P, n, m)."""
        g = -np.swapaxes(self.dof_map, -1, -2)
        if self.reacts is not None:
            g = g * self.reacts[:, None]
        return g

    def deformation(self, q: np.ndarray, u: np.ndarray | None) -> np.ndarray:
        """δ (or δ̇ from rates) of the group, (m, P, S)."""
        d = apply(self.dof_map, q)
        if u is not None and self.input_map.any():
            d = d + apply(self.input_map, u)
        return d

    def parts(self, q, v, u, u_dot, damping=None) -> tuple[np.ndarray, np.ndarray]:
        """The elastic part ``k δ + F_x`` and the damping part ``c δ̇`` of the elements' force,
        (m, P, S) each [N]; ``damping`` (m, P, 1|S) replaces c (a semi-active damper)."""
        return self.parts_at(self.deformation(q, u), self.deformation(v, u_dot), damping)

    def parts_at(self, disp, rate, damping=None) -> tuple[np.ndarray, np.ndarray]:
        """:meth:`parts` from the deformations ``δ, δ̇`` (m, P, S)."""
        elastic = self.stiffness * disp
        viscous = (self.damping if damping is None else damping) * rate
        if self.extra is not None:
            extra = np.empty(np.broadcast_shapes(elastic.shape, viscous.shape))
            self.extra(disp.shape[1])(disp, rate, elastic + viscous, extra)
            elastic = elastic + extra
        return elastic, viscous


@dataclass
class LinearModel:
    """A network linearised about rest: ``M q̈ + C q̇ + K q = B_k u + B_c u̇``.

    ``mass (P, n)`` the diagonal of M; ``stiffness``, ``damping (P, n, n)``;
    ``input_stiffness``, ``input_damping (P, n, n_u)``. Units SI (N/m, N s/m, ...).
    """

    dof_names: tuple[str, ...]
    input_names: tuple[str, ...]
    mass: np.ndarray
    stiffness: np.ndarray
    damping: np.ndarray
    input_stiffness: np.ndarray
    input_damping: np.ndarray


@dataclass
class Network:
    """DOFs ``dof_names`` with masses ``mass (n, P, 1)`` [kg, kg m²], inputs ``input_names``,
    and the element ``groups`` acting on them (see the module docstring)."""

    dof_names: tuple[str, ...]
    input_names: tuple[str, ...]
    mass: np.ndarray
    groups: tuple[Elements, ...]

    @property
    def n(self) -> int:
        return len(self.dof_names)

    @property
    def P(self) -> int:
        return max([self.mass.shape[1]] + [g.stiffness.shape[1] for g in self.groups])

    def group(self, name: str) -> Elements:
        for g in self.groups:
            if g.name == name:
                return g
        raise KeyError(name)

    def forces(self, q: np.ndarray, v: np.ndarray, u: np.ndarray | None = None,
               u_dot: np.ndarray | None = None,
               damping: Mapping[str, np.ndarray] | None = None
               ) -> dict[str, tuple[np.ndarray, np.ndarray]]:
        """Every group's ``(elastic, viscous)`` force parts (m, P, S) [N] for the states
        ``q, v (n, P, S)`` and inputs ``u, u_dot (n_u, 1|P, S)``; ``damping`` maps group
        names to coefficients that replace theirs."""
        damping = damping or {}
        return {g.name: g.parts(q, v, u, u_dot, damping.get(g.name)) for g in self.groups}

    def generalised_forces(self, q, v, u=None, u_dot=None, damping=None
                           ) -> tuple[np.ndarray, np.ndarray]:
        """``-Σ D_qᵀ F`` on the DOFs (n, P, S) [N, N m] and ``-Σ D_uᵀ F`` on the inputs
        (n_u, P, S) [N] (the reaction on the road or the floor), from one evaluation of the
        element forces."""
        shape = np.broadcast_shapes(q.shape[1:], v.shape[1:])
        dofs = np.zeros((self.n,) + shape)
        inputs = np.zeros((len(self.input_names),) + shape)
        for g, (elastic, viscous) in zip(self.groups,
                                          self.forces(q, v, u, u_dot, damping).values()):
            force = elastic + viscous
            dofs += apply(g.force_map, force)
            inputs -= apply(g.input_map.T, force)
        return dofs, inputs

    def linear_model(self) -> LinearModel:
        """Linear matrices about rest: each group adds ``D_qᵀ diag(k + dF_x/dδ) D_q`` to K,
        ``D_qᵀ diag(c) D_q`` to C and ``-D_qᵀ diag(k) D_u`` (``c``) to B_k (B_c); the
        mask ``reacts`` applies to the rows."""
        P, n, nu = self.P, self.n, len(self.input_names)
        K, C = np.zeros((P, n, n)), np.zeros((P, n, n))
        Bk, Bc = np.zeros((P, n, nu)), np.zeros((P, n, nu))
        for g in self.groups:
            G = np.broadcast_to(g.force_map, (P, n, g.size))
            Dq = np.broadcast_to(g.dof_map, (P, g.size, n))
            k = g.stiffness[:, :, 0].T
            if g.extra_slope is not None:
                k = k + g.extra_slope[:, :, 0].T
            c = g.damping[:, :, 0].T
            K -= np.einsum("pim,pm,pmj->pij", G, k, Dq)
            C -= np.einsum("pim,pm,pmj->pij", G, c, Dq)
            if nu:
                Bk += np.einsum("pim,pm,mj->pij", G, g.stiffness[:, :, 0].T, g.input_map)
                Bc += np.einsum("pim,pm,mj->pij", G, c, g.input_map)
        return LinearModel(self.dof_names, self.input_names,
                           np.broadcast_to(self.mass[:, :, 0].T, (P, n)).copy(), K, C, Bk, Bc)

    def attach(self, other: "Network", point: np.ndarray, coupled: bool) -> "Network":
        """This network with ``other`` mounted on it: ``other``'s single input (its floor)
        follows ``point @ q`` (``point (n,)``: the body's vertical displacement at the mount
        per DOF of this network); ``coupled`` puts the floor's reaction on this network's DOFs,
        else ``other`` is driven one way (the thesis's seats)."""
        if len(other.input_names) != 1:
            raise ValueError("an attached network needs exactly one input (its floor)")
        n, m = self.n, other.n
        own = tuple(replace(g, dof_map=_pad(g.dof_map, 0, m),
                            reacts=None if g.reacts is None else np.r_[g.reacts, np.ones(m, bool)])
                    for g in self.groups)
        mounted = []
        for g in other.groups:
            floor = g.input_map[:, 0]
            onto_body = floor[:, None] * point[None, :]
            dof_map = np.concatenate([np.broadcast_to(onto_body, g.dof_map.shape[:-2]
                                                      + onto_body.shape), g.dof_map], axis=-1)
            reacts = np.r_[np.full(n, coupled), np.ones(m, bool) if g.reacts is None
                           else g.reacts]
            mounted.append(replace(g, dof_map=dof_map,
                                   input_map=np.zeros((g.size, len(self.input_names))),
                                   reacts=None if reacts.all() else reacts))
        P = max(self.mass.shape[1], other.mass.shape[1])
        mass = np.concatenate([np.broadcast_to(self.mass, (n, P, 1)),
                               np.broadcast_to(other.mass, (m, P, 1))])
        return Network(self.dof_names + other.dof_names, self.input_names, mass,
                       own + tuple(mounted))


def _pad(matrix: np.ndarray, before: int, after: int) -> np.ndarray:
    """Zero columns around a (.., m, n) map."""
    widths = [(0, 0)] * (matrix.ndim - 1) + [(before, after)]
    return np.pad(matrix, widths)

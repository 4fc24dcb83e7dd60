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
The simulator integrates the assembled network (:mod:`suspopt.simulation`), and the linear
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

__all__ = [
    "Elements",
    "Network",
    "LinearModel",
    "Assembled",
    "apply",
    "parameter_rows",
    "shared_rows",
    "widen",
    "frequencies",
    "check_response_memory",
]

#: Frequencies solved at a time by :meth:`LinearModel.frequency_response` (bounds the memory
#: of its (P, F, n, n) matrices).
_BLOCK = 256


def frequencies(f) -> np.ndarray:
    """``f`` as a float array of frequencies ``(F,)`` [Hz]; ValueError unless it is 1-D (or
    one value), finite and >= 0."""
    f = np.atleast_1d(np.asarray(f, dtype=float))
    if f.ndim != 1:
        raise ValueError(f"f must be a 1-D array of frequencies [Hz]; got shape {f.shape}")
    bad = np.flatnonzero(~(np.isfinite(f) & (f >= 0)))
    if bad.size:
        raise ValueError(f"f must be finite and >= 0 [Hz]; f[{bad[0]}] is {f[bad[0]]}")
    return f


def check_response_memory(P: int, F: int, n: int, inputs: int) -> None:
    """ConfigError when a frequency response of P designs at F frequencies (n DOFs, its
    inputs' amplitudes given) would take more memory than the limit
    (:func:`suspopt.memory.check`): the amplitudes ``(P, F, n)``, the inputs ``(F, n_u)``
    and one block's matrices."""
    from . import memory

    memory.check(
        16.0 * (P * F * n + F * inputs + P * _BLOCK * n * (n + inputs + 2)),
        f"the frequency response of {P} designs at {F} frequencies",
        "give fewer frequencies or designs at once",
    )


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


def shared_rows(a: np.ndarray) -> np.ndarray:
    """Collapse a (P, ...) array to (1, ...) when every design has the same values."""
    return a[:1] if a.shape[0] > 1 and np.array_equal(a, np.broadcast_to(a[:1], a.shape)) else a


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
    DOFs that feel the group's force (None: all - a one-way seat's links do not push the body);
    ``extra_law`` the same F_x as a law the compiled integrator knows
    (:data:`suspopt.integrator.compiled.LAWS`), ``(name, parameters)`` with each parameter
    (m, P, 1), or None (the numpy integrator only).
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
    extra_law: tuple[str, tuple[np.ndarray, ...]] | None = None

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

    @property
    def P(self) -> int:
        return self.mass.shape[0]

    def part(self, dofs: slice) -> LinearModel:
        """The DOFs ``dofs`` alone, the others held still (their coupling terms dropped)."""
        return LinearModel(
            self.dof_names[dofs],
            self.input_names,
            self.mass[:, dofs],
            self.stiffness[:, dofs, dofs],
            self.damping[:, dofs, dofs],
            self.input_stiffness[:, dofs],
            self.input_damping[:, dofs],
        )

    def frequency_response(self, f: np.ndarray, inputs: np.ndarray | None = None) -> np.ndarray:
        """Complex DOF amplitudes ``Q (P, F, n)`` under harmonic inputs ``u = R exp(jωt)``:
        ``(K - ω² M + jω C) Q = (B_k + jω B_c) R``.

        ``f (F,)`` [Hz]; ``inputs (F, n_u)`` the complex input amplitudes ``R`` per frequency
        [m] (default: a unit amplitude on every input). Accelerations are ``-ω² Q``; for a
        unit input displacement, ``Q`` is also the acceleration ratio to the input's.
        """
        f = frequencies(f)
        n, nu = len(self.dof_names), self.input_stiffness.shape[-1]
        R = np.ones((f.size, nu)) if inputs is None else np.asarray(inputs)
        if R.shape != (f.size, nu):
            raise ValueError(f"inputs must be (F, n_u) = {(f.size, nu)}; got shape {R.shape}")
        check_response_memory(self.P, f.size, n, nu)
        Q = np.empty((self.P, f.size, n), complex)
        for start in range(0, f.size, _BLOCK):  # (bounds the (P, F, n, n) matrices)
            w = 2.0 * np.pi * f[None, start : start + _BLOCK, None, None]
            dyn = (
                self.stiffness[:, None]
                - w**2 * (self.mass[:, None, :, None] * np.eye(n))
                + 1j * w * self.damping[:, None]
            )
            B = self.input_stiffness[:, None] + 1j * w * self.input_damping[:, None]
            rhs = B @ R[None, start : start + _BLOCK, :, None]  # (P or 1, F, n, 1)
            Q[:, start : start + _BLOCK] = np.linalg.solve(dyn, rhs)[..., 0]
        return Q

    def modal_form(self) -> tuple[np.ndarray, ...]:
        """The state matrix ``A = [[0, I], [-M^-1 K, -M^-1 C]]`` decomposed for
        :meth:`modal_response`: eigenvalues ``λ (P, 2n)``, the displacement rows of the
        eigenvectors ``V_q (P, n, 2n)``, the modal input maps ``V^-1 [0; M^-1 B_k]`` and
        ``V^-1 [0; M^-1 B_c]`` (P, 2n, n_u), and the designs whose ``V`` is ill-conditioned
        (a nearly defective ``A``, as at critical damping) ``(P,)``."""
        P, n = self.P, len(self.dof_names)
        inverse = 1.0 / self.mass[:, :, None]
        A = np.zeros((P, 2 * n, 2 * n))
        A[:, :n, n:] = np.eye(n)
        A[:, n:, :n], A[:, n:, n:] = -inverse * self.stiffness, -inverse * self.damping
        lam, V = np.linalg.eig(A)
        V_inv = np.linalg.inv(V)
        W0 = V_inv[:, :, n:] @ (inverse * self.input_stiffness)
        W1 = V_inv[:, :, n:] @ (inverse * self.input_damping)
        return lam, V[:, :n, :], W0, W1, np.linalg.cond(V) > 1e8

    def modal_response(self, f: np.ndarray, inputs: np.ndarray, form=None) -> np.ndarray:
        """:meth:`frequency_response` by the eigen-decomposition ``form`` of
        :meth:`modal_form` (made when None): ``Q = V_q diag(1/(jω - λ)) V^-1 b(ω)`` with
        ``b = [0; M^-1 (B_k + jω B_c) R]``, a few products per frequency instead of a solve;
        the designs whose ``V`` is ill-conditioned take the solve. Same arguments and result
        ``(P, F, n)`` as :meth:`frequency_response`."""
        f = np.atleast_1d(np.asarray(f, dtype=float))
        lam, Vq, W0, W1, bad = self.modal_form() if form is None else form
        R = np.asarray(inputs).T  # (n_u, F)
        jw = 1j * (2.0 * np.pi * f)
        modal = (W0 @ R + jw * (W1 @ R)) / (jw[None, None, :] - lam[:, :, None])  # (P, 2n, F)
        Q = np.swapaxes(Vq @ modal, 1, 2)
        if bad.any():
            part = LinearModel(
                self.dof_names, self.input_names, self.mass[bad], self.stiffness[bad],
                self.damping[bad], self.input_stiffness[bad], self.input_damping[bad],
            )  # fmt: skip
            Q[bad] = part.frequency_response(f, inputs)
        return Q

    def modes(self) -> tuple[np.ndarray, np.ndarray]:
        """Undamped natural frequencies ``(P, n)`` [Hz], ascending, and mode shapes
        ``(P, n, n)`` (columns, in the DOFs' own units) of ``K φ = ω² M φ``, inputs held still;
        solved as the symmetric ``M^-1/2 K M^-1/2`` (M diagonal), batched over designs."""
        s = 1.0 / np.sqrt(self.mass)
        lam, vec = np.linalg.eigh(s[:, :, None] * self.stiffness * s[:, None, :])
        return np.sqrt(np.clip(lam, 0.0, None)) / (2.0 * np.pi), s[:, :, None] * vec


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

    def forces(
        self,
        q: np.ndarray,
        v: np.ndarray,
        u: np.ndarray | None = None,
        u_dot: np.ndarray | None = None,
        damping: Mapping[str, np.ndarray] | None = None,
    ) -> dict[str, tuple[np.ndarray, np.ndarray]]:
        """Every group's ``(elastic, viscous)`` force parts (m, P, S) [N] for the states
        ``q, v (n, P, S)`` and inputs ``u, u_dot (n_u, 1|P, S)``; ``damping`` maps group
        names to coefficients that replace theirs."""
        damping = damping or {}
        return {g.name: g.parts(q, v, u, u_dot, damping.get(g.name)) for g in self.groups}

    def generalised_forces(
        self, q, v, u=None, u_dot=None, damping=None
    ) -> tuple[np.ndarray, np.ndarray]:
        """``-Σ D_qᵀ F`` on the DOFs (n, P, S) [N, N m] and ``-Σ D_uᵀ F`` on the inputs
        (n_u, P, S) [N] (the reaction on the road or the floor), from one evaluation of the
        element forces."""
        shape = np.broadcast_shapes(q.shape[1:], v.shape[1:])
        dofs = np.zeros((self.n,) + shape)
        inputs = np.zeros((len(self.input_names),) + shape)
        for g, (elastic, viscous) in zip(
            self.groups, self.forces(q, v, u, u_dot, damping).values()
        ):
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
        return LinearModel(
            self.dof_names,
            self.input_names,
            np.broadcast_to(self.mass[:, :, 0].T, (P, n)).copy(),
            K,
            C,
            Bk,
            Bc,
        )

    def attach(self, other: Network, point: np.ndarray, coupled: bool) -> Network:
        """This network with ``other`` mounted on it: ``other``'s single input (its floor)
        follows ``point @ q`` (``point (n,)``: the body's vertical displacement at the mount
        per DOF of this network); ``coupled`` puts the floor's reaction on this network's DOFs,
        else ``other`` is driven one way (the thesis's seats)."""
        if len(other.input_names) != 1:
            raise ValueError("an attached network needs exactly one input (its floor)")
        n, m = self.n, other.n
        own = tuple(
            replace(
                g,
                dof_map=_pad(g.dof_map, 0, m),
                reacts=None if g.reacts is None else np.r_[g.reacts, np.ones(m, bool)],
            )
            for g in self.groups
        )
        mounted = []
        for g in other.groups:
            floor = g.input_map[:, 0]
            onto_body = floor[:, None] * point[None, :]
            dof_map = np.concatenate(
                [np.broadcast_to(onto_body, g.dof_map.shape[:-2] + onto_body.shape), g.dof_map],
                axis=-1,
            )
            reacts = np.r_[np.full(n, coupled), np.ones(m, bool) if g.reacts is None else g.reacts]
            mounted.append(
                replace(
                    g,
                    dof_map=dof_map,
                    input_map=np.zeros((g.size, len(self.input_names))),
                    reacts=None if reacts.all() else reacts,
                )
            )
        P = max(self.mass.shape[1], other.mass.shape[1])
        mass = np.concatenate(
            [np.broadcast_to(self.mass, (n, P, 1)), np.broadcast_to(other.mass, (m, P, 1))]
        )
        return Network(
            self.dof_names + other.dof_names, self.input_names, mass, own + tuple(mounted)
        )


def _pad(matrix: np.ndarray, before: int, after: int) -> np.ndarray:
    """Zero columns around a (.., m, n) map."""
    widths = [(0, 0)] * (matrix.ndim - 1) + [(before, after)]
    return np.pad(matrix, widths)


def _product(matrix: np.ndarray, x: np.ndarray, out: np.ndarray) -> None:
    """``out = matrix @ x`` for a (P, r, c) matrix per design and columns ``x (c, P)``."""
    np.einsum("prc,cp->rp", matrix, x, out=out)


class Assembled:
    """A network packed for fast evaluation of ``q'' = M^-1 Σ -D_qᵀ F`` (suspopt.network).

    All groups' deformation rows are stacked: ``e = D2 @ [q; v] + offset`` gives the
    displacements (rows ``:R``) and rates (rows ``R:``) of every element, ``F = coef * e`` their
    elastic and viscous forces (``coef = [k; c]``), the groups' non-linear parts are added to
    the elastic rows, and ``q'' = M^-1 G2 @ F`` with ``G2 = [G, G]`` (``G = -D_qᵀ``, masked
    where a one-way seat does not push the body). ``offset`` holds the inputs' part
    ``[D_u u; D_u u']``. A semi-active damper's coefficients are the rows ``damper_rows`` of
    ``coef``. The deformation and force maps are shared by all designs unless a group's map
    differs between them (``(P, ...)`` arrays, multiplied per design by :func:`_product`).
    """

    def __init__(self, network: Network, P: int, controlled: str | None = None):
        self.network = network
        n, groups = network.n, network.groups
        R = sum(g.size for g in groups)
        self.n, self.R, self.P = n, R, P
        per_design = any(g.dof_map.ndim == 3 for g in groups)
        dq = [
            np.broadcast_to(g.dof_map, (P, g.size, n)) if per_design else g.dof_map for g in groups
        ]
        Dq = np.concatenate(dq, axis=-2)
        D2 = np.zeros(Dq.shape[:-2] + (2 * R, 2 * n))
        D2[..., :R, :n] = Dq
        D2[..., R:, n:] = Dq
        self.input_map = np.concatenate([g.input_map for g in groups])  # (R, n_u)
        G = np.concatenate(
            [
                np.broadcast_to(g.force_map, (P, n, g.size)) if per_design else g.force_map
                for g in groups
            ],
            axis=-1,
        )
        # the non-linear parts are forces of their own rows of F, acting like their elements
        extra_rows = np.concatenate(
            [
                np.arange(start, start + g.size)
                for start, g in zip(np.cumsum([0] + [g.size for g in groups]), groups)
                if g.extra is not None
            ]
            or [np.arange(0)]
        )
        G2 = np.concatenate([G, G, G[..., extra_rows]], axis=-1)
        # M^-1 multiplies the accelerations even where it could be folded into G2: folding
        # rounds differently, and a design must give the same bits whatever else varies in
        # its batch
        self.inverse_mass = np.ascontiguousarray(1.0 / np.broadcast_to(network.mass, (n, P, 1)))
        self.D2, self.G2 = np.ascontiguousarray(D2), np.ascontiguousarray(G2)
        self.coef = np.ascontiguousarray(
            np.concatenate(
                [np.broadcast_to(g.stiffness, (g.size, P, 1)) for g in groups]
                + [np.broadcast_to(g.damping, (g.size, P, 1)) for g in groups]
            )
        )
        self.extras, self.damper_rows, start, out = [], None, 0, 2 * R
        for g in groups:
            rows = slice(start, start + g.size)
            rates = slice(R + start, R + start + g.size)
            if g.extra is not None:
                self.extras.append(
                    (rows, rates, slice(out, out + g.size), g.extra, g.extra_uses_force)
                )
                out += g.size
            if g.name == controlled:
                self.damper_rows = rates
            start += g.size
        self.F_rows = out

    def offsets(self, u: np.ndarray, u_dot: np.ndarray) -> np.ndarray:
        """``[D_u u; D_u u']`` at each sample of the inputs ``u, u_dot (n_u, T)``: (T, 2R,
        1, 1), contiguous per sample."""
        off = np.concatenate([self.input_map @ u, self.input_map @ u_dot])
        return np.ascontiguousarray(off.T)[:, :, None, None]

    def evaluator(
        self, width: int | None = None
    ) -> Callable[..., None]:  # (y2, offset or None, coef, inverse_mass, acc2, acc)
        """A function ``(y2, offset, coef, inverse_mass, acc2, acc) -> None`` that writes
        ``q''`` of ``width`` design columns (default P) into ``acc``.

        ``y2 = [q; v]`` (2n, width); ``offset`` (2R, 1|width, 1), or (2R, G, 1) for G
        roads, each under its own block of ``width / G`` consecutive columns, or None where
        the inputs are zero; ``coef`` (2R, width, 1);
        ``inverse_mass`` (n, width, 1), scaled when the caller wants a multiple of q'';
        ``acc2``/``acc`` the (n, width) and (n, width, 1) views of the output. Its buffers for
        the deformations and forces are allocated once, with the non-linear parts' views into
        them, so that the integrator's stages allocate nothing.
        """
        R, width = self.R, width or self.P
        e, F = np.empty((2 * R, width, 1)), np.empty((self.F_rows, width, 1))
        e2, F2, linear = e.reshape(2 * R, -1), F.reshape(self.F_rows, -1), F[: 2 * R]
        extras = [
            (F[rows], F[rates], e[rows], e[rates], F[out], make(width), uses)
            for rows, rates, out, make, uses in self.extras
        ]
        product = np.dot if self.D2.ndim == 2 else _product
        D2, G2, multiply, add = self.D2, self.G2, np.multiply, np.add

        def evaluate(y2, offset, coef, inverse_mass, acc2, acc) -> None:
            product(D2, y2, out=e2)
            if offset is not None:
                if offset.shape[1] in (1, width):
                    e.__iadd__(offset)
                else:  # a road per block of columns
                    e.reshape(2 * R, offset.shape[1], -1).__iadd__(offset)
            multiply(coef, e, out=linear)
            for elastic, viscous, disp, rate, out, fn, uses_force in extras:
                fn(disp, rate, add(elastic, viscous) if uses_force else None, out)
            product(G2, F2, out=acc2)
            acc.__imul__(inverse_mass)

        return evaluate

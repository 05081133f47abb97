"""Simultaneous rigid impacts and stuck contacts, resolved together (docs/numerics.md, "Rigid contacts").

When instantaneous (stereo-mechanical) contacts close at one instant, or one
closes while others are stuck (persistent), their impulses act through shared
floors and must be found together.  The impact law is **Newton's restitution
per contact, as a linear complementarity problem** (Moreau 1988; Pfeiffer &
Glocker 1996, ch. 7; Brogliato 2016, §5.2): with ``w`` the contacts' approach
rates δ̇ before the impulses ``P`` (N·s, ≥ 0 push apart) and the Delassus
matrix ``G = W M⁻¹ Wᵀ`` (1/kg) of the contacts' side weights ``W``,

    w⁺ = w − G P,     s = G P − b ≥ 0,   P ≥ 0,   sᵀP = 0,
    b_c = w_c + e_c·max(w_c, 0),

i.e. every contact leaves at least ``e_c`` times as fast as it came in
(``−w⁺_c ≥ e_c·w_c``), and pushes only where it must (a contact that
separates by itself takes no impulse).  ``e_c = 0`` for a stuck contact and
for a closure at or below the law's rest velocity (a plastic impact, that
may then stick).  G is symmetric positive semi-definite, so the problem has a
solution; it is found by projected Gauss–Seidel and then made exact on its
active set.  Sequential pairwise impulses are not used: where one plastic
impact changes a shared floor's velocity, a contact stuck on that floor would
start to penetrate.
"""

from __future__ import annotations

from numba import njit

from pounding.solver import jit

__all__ = ["delassus", "solve_lcp", "LCP_SWEEPS"]

#: Projected Gauss–Seidel sweeps before the active set is solved exactly.
LCP_SWEEPS = 500


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)
def delassus(mass, cf, cw, width, active, na, G) -> None:
    """``G[i, j] = Σ_k Σ_l w_k·w_l / m_f`` over the floor terms k of contact active[i] and l of
    active[j] on the same floor f (1/kg), for i, j < *na*: the change of contact i's δ̇ per unit
    impulse of j."""
    for i in range(na):
        ci = active[i]
        for j in range(na):
            cj = active[j]
            total = 0.0
            for k in range(len(width) * ci, len(width) * ci + len(width)):
                if cw[k] == 0.0:
                    continue
                for m in range(len(width) * cj, len(width) * cj + len(width)):
                    if cw[m] != 0.0 and cf[m] == cf[k]:
                        total += cw[k] * cw[m] / mass[cf[k]]
            G[i, j] = total


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)
def _solve_active(rigid, na) -> bool:
    """Solve ``G_II P_I = b_I`` on the active set I = {P > 0} into ``rigid.exact`` (Gaussian
    elimination with partial pivoting); False if it is singular there."""
    G, b, P, exact, index, A = rigid.delassus, rigid.target, rigid.impulse, rigid.exact, rigid.index, rigid.system
    m = 0
    for i in range(na):
        exact[i] = 0.0
        if P[i] > 0.0:
            index[m] = i
            m += 1
    for r in range(m):
        for col in range(m):
            A[r, col] = G[index[r], index[col]]
        A[r, m] = b[index[r]]
    for col in range(m):
        pivot = col
        for r in range(col + 1, m):
            if abs(A[r, col]) > abs(A[pivot, col]):
                pivot = r
        if A[pivot, col] == 0.0:
            return False
        if pivot != col:
            for k in range(m + 1):
                A[col, k], A[pivot, k] = A[pivot, k], A[col, k]
        for r in range(col + 1, m):
            f = A[r, col] / A[col, col]
            for k in range(col, m + 1):
                A[r, k] -= f * A[col, k]
    for r in range(m - 1, -1, -1):
        acc = A[r, m]
        for k in range(r + 1, m):
            acc -= A[r, k] * exact[index[k]]
        exact[index[r]] = acc / A[r, r]
    return True


@njit(cache=True, no_cpython_wrapper=True, no_cfunc_wrapper=True, **jit.CALLED, **jit.NO_REFCOUNT)
def solve_lcp(rigid, na) -> None:
    """Impulses ``P ≥ 0`` (N·s) with ``s = G P − b ≥ 0`` and ``sᵀP = 0`` (module docstring) into
    ``rigid.impulse[:na]``, from ``rigid.delassus`` and ``rigid.target``.

    Projected Gauss–Seidel (convergent for a symmetric positive semi-definite G
    with positive diagonal) finds the active set; the equations on it are then
    solved exactly, and that solution is kept if it is feasible (P ≥ 0, s ≥ 0 to
    round-off), else the Gauss–Seidel one.
    """
    G, b, P, exact = rigid.delassus, rigid.target, rigid.impulse, rigid.exact
    scale = 0.0
    for i in range(na):
        P[i] = 0.0
        scale = max(scale, abs(b[i]) / G[i, i])
    if scale == 0.0:
        return
    for _ in range(LCP_SWEEPS):
        change = 0.0
        for i in range(na):
            residual = b[i]
            for j in range(na):
                residual -= G[i, j] * P[j]
            new = max(0.0, P[i] + residual / G[i, i])
            change = max(change, abs(new - P[i]))
            P[i] = new
        if change <= 1e-15 * scale:
            break
    if not _solve_active(rigid, na):
        return
    for i in range(na):
        s = -b[i]
        for j in range(na):
            s += G[i, j] * exact[j]
        if exact[i] < 0.0 or s < -1e-12 * G[i, i] * scale:
            return
    for i in range(na):
        P[i] = exact[i]


jit.stamp_solver_kernels(globals())

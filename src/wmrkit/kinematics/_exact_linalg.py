"""Exact linear algebra for the symbolic models: rational-function fields with sin^2 + cos^2 = 1 (private).

Entries of the constraint matrix are polynomials in sin/cos of a few angles and in geometry symbols. Replacing
each sin/cos (and each square root) by a polynomial variable turns the ranks method (4.9)-(4.11) into linear
algebra over a polynomial ring, which sympy's ``DomainMatrix.solve_den`` does exactly and fraction-free (one
common denominator per block, no gcd per operation); each entry is then reduced modulo the relations
``s^2 + c^2 - 1`` and ``g^2 - n`` and cancelled once. Ranks and row choices are generic: taken numerically at
random values of every symbol, and the closed form is checked against numeric least squares at another point.
"""

from __future__ import annotations

import numpy as np
import sympy as sp
from sympy.polys.domains import FractionField, PolynomialRing
from sympy.polys.matrices import DomainMatrix

from .linalg import matrix_rank


class _Generators:
    """Polynomial generators for sin/cos of each argument and for square roots, with their relations.

    ``s^2 + c^2 - 1`` per argument and ``g^2 - n`` per ``sqrt(n)``: pairwise coprime leading terms, so they are a
    Groebner basis and reducing modulo them gives a normal form (zero iff the entry vanishes identically).
    """

    def __init__(self, exprs: list[sp.Expr], *, enabled: bool = True) -> None:
        atoms = set().union(*(e.atoms(sp.sin, sp.cos) for e in exprs)) if enabled else set()
        roots = {p for e in exprs for p in e.atoms(sp.Pow) if p.base.is_Integer and p.exp == sp.S.Half}
        roots = roots if enabled else set()
        self.forward: dict[sp.Expr, sp.Symbol] = {}
        self.back: dict[sp.Symbol, sp.Expr] = {}
        self.relations: list[sp.Expr] = []
        self._bases: dict = {}
        for k, arg in enumerate(sorted({a.args[0] for a in atoms}, key=sp.default_sort_key)):
            s, c = sp.Dummy(f"a{k}"), sp.Dummy(f"b{k}")  # sin before cos: reducing gives s^2 -> 1 - c^2
            self.forward.update({sp.sin(arg): s, sp.cos(arg): c})
            self.back.update({s: sp.sin(arg), c: sp.cos(arg)})
            self.relations.append(s**2 + c**2 - 1)
        for k, root in enumerate(sorted(roots, key=sp.default_sort_key)):
            g = sp.Dummy(f"g{k}")
            self.forward[root], self.back[g] = g, root
            self.relations.append(g**2 - root.base)

    def _basis(self, ring) -> list:
        """The relations as polynomials of `ring`, built once per ring: rebuilding them for every entry (a
        conversion per relation, 221,760 for 32 double wheels) took most of the time of a large closed form."""
        if ring not in self._bases:
            self._bases[ring] = [ring.from_expr(r) for r in self.relations if r.free_symbols <= set(ring.symbols)]
        return self._bases[ring]

    def domain_matrix(self, m: sp.MatrixBase) -> DomainMatrix:
        """`m` over a ring of polynomials in the generators (and the other symbols), or numbers (QQ, EX)."""
        return DomainMatrix.from_list_sympy(*m.shape, sp.Matrix(m).xreplace(self.forward).tolist())

    def fraction(self, num, den, domain) -> sp.Expr:
        """``num / den`` (elements of `domain`) reduced modulo the relations, cancelled, as sin/cos and roots."""
        ring = _poly_ring(domain)
        if ring is None:
            return sp.factor_terms(sp.cancel(domain.to_sympy(num) / domain.to_sympy(den))).xreplace(self.back)
        num, den = num.rem(self._basis(ring)), den.rem(self._basis(ring))
        if not den:
            raise ZeroDivisionError("a pivot vanished on sin^2 + cos^2 = 1")
        num, den = num.cancel(den)
        signs = [1 if c > 0 else -1 for c in den.coeffs()]
        if sum(signs) < 0 or (sum(signs) == 0 and den.coeff(1) < 0):  # prefer 4 - 3 c^2 to 3 c^2 - 4
            num, den = -num, -den
        return sp.factor_terms(num.as_expr() / den.as_expr()).xreplace(self.back)


def _poly_ring(domain):
    if isinstance(domain, PolynomialRing):
        return domain.ring
    if isinstance(domain, FractionField):
        return domain.field.ring
    return None


def numeric(m: sp.MatrixBase, point: dict[sp.Symbol, sp.Float]) -> np.ndarray:
    return np.array(sp.Matrix(m).xreplace(point).evalf(), dtype=float).reshape(m.shape)


def equilibrated(values: np.ndarray) -> np.ndarray:
    """`values` with each non-zero column divided by its largest entry: ranks and independent rows are decided on
    columns of order 1 whatever the units (m/s of vx, m of a radius), as on the nondimensional robot of the numeric
    models (``linalg.nondimensional``). Raw, a 1 um robot's castor of radius 1 nm fell below the rank tolerance."""
    size = np.abs(values).max(axis=-2, keepdims=True)
    return values / np.where(size > 0, size, 1.0)


def random_points(m: sp.MatrixBase, n: int = 2) -> list[dict[sp.Symbol, sp.Float]]:
    rng = np.random.default_rng(20240607)
    symbols = sorted(m.free_symbols, key=sp.default_sort_key)
    return [{s: sp.Float(v) for s, v in zip(symbols, rng.uniform(0.3, 1.3, len(symbols)), strict=True)}
            for _ in range(n)]


def _components(a_na: sp.MatrixBase) -> list[tuple[list[int], list[int]]]:
    """Blocks of unknowns coupled through shared rows, as ``(rows, columns)``: solved one by one."""
    parent = list(range(a_na.cols))

    def root(j: int) -> int:
        while parent[j] != j:
            j = parent[j]
        return j

    for i in range(a_na.rows):
        cols = [j for j in range(a_na.cols) if a_na[i, j] != 0]
        for j in cols[1:]:
            parent[root(j)] = root(cols[0])
    blocks: dict[int, list[int]] = {}
    for j in range(a_na.cols):
        blocks.setdefault(root(j), []).append(j)
    return [([i for i in range(a_na.rows) if any(a_na[i, j] != 0 for j in cols)], cols) for cols in blocks.values()]


def agrees(m: sp.MatrixBase, a: sp.MatrixBase, na_idx: list[int], a_idx: list[int],
            point: dict[sp.Symbol, sp.Float]) -> bool:
    """The closed form equals the numeric least-squares solution (4.11) at a random point."""
    values = numeric(a, point)
    expected = -np.linalg.lstsq(values[:, na_idx], values[:, a_idx], rcond=None)[0]
    return bool(np.allclose(numeric(m, point), expected, rtol=1e-8, atol=1e-10))


def generic_ranks(a: sp.MatrixBase, na_idx: list[int]) -> tuple[list, list[np.ndarray], int, list[int]]:
    """Two random points of `a`'s symbols, its values there (columns equilibrated), its generic rank and the ranks
    of its columns `na_idx` at each point."""
    points = random_points(a)
    values = [equilibrated(numeric(a, p)) for p in points]  # ranks of columns of order 1 (units, tiny robots)
    return points, values, max(int(matrix_rank(v)) for v in values), [int(matrix_rank(v[:, na_idx])) for v in values]


def closed_form(a: sp.MatrixBase, na_idx: list[int], a_idx: list[int], exact: bool, values: list[np.ndarray],
                points: list) -> tuple[sp.Matrix, sp.Matrix]:
    """:func:`solve_exactly` checked against numeric least squares at the second point; a pivot that vanishes only
    on sin^2 + cos^2 = 1 is redone over plain expressions (slower)."""
    try:
        m, residual = solve_exactly(a, na_idx, a_idx, exact, values[0])
        ok = agrees(m, a, na_idx, a_idx, points[1])
    except ZeroDivisionError:
        ok = False
    if not ok:
        m, residual = solve_exactly(a, na_idx, a_idx, exact, values[0], generators=False)
    return m, residual


def _independent_rows(values: np.ndarray, rows: list[int], cols: list[int]) -> list[int]:
    chosen: list[int] = []
    for i in rows:
        if matrix_rank(values[np.ix_([*chosen, i], cols)]) > len(chosen):
            chosen.append(i)
        if len(chosen) == len(cols):
            break
    return chosen


def solve_exactly(a: sp.MatrixBase, na_idx: list[int], a_idx: list[int], exact: bool,
                  values: np.ndarray, *, generators: bool = True) -> tuple[sp.Matrix, sp.Matrix]:
    """``M`` with ``q_na = M q_a`` and the residual ``A_na M + A_a``, block by block, fraction-free.

    Each block is solved as ``lhs X = rhs`` with one common denominator (``DomainMatrix.solve_den``, no gcd per
    operation); exact: a maximal independent set of rows (4.5); least squares: the normal equations (4.11).
    With `generators`, sin/cos and roots are polynomial variables (fast); without, sympy expressions (EX).
    """
    gens = _Generators(list(a), enabled=generators)
    full = gens.domain_matrix(a)
    domain, all_rows, all_a = full.domain, list(range(a.rows)), list(range(len(a_idx)))
    a_na, a_a = full.extract(all_rows, na_idx), full.extract(all_rows, a_idx)
    m = sp.zeros(len(na_idx), len(a_idx))
    residual = sp.zeros(a.rows, len(a_idx))
    covered: set[int] = set()
    for rows, cols in _components(a[:, na_idx]):
        covered.update(rows)
        if not a_idx:
            continue
        block, b = a_na.extract(rows, cols), a_a.extract(rows, all_a)
        if exact:
            keep = _independent_rows(values[:, na_idx], rows, cols)
            lhs, rhs = a_na.extract(keep, cols), a_a.extract(keep, all_a)
        else:
            lhs, rhs = block.transpose() * block, block.transpose() * b
        x, den = lhs.solve_den(rhs)  # lhs x = rhs den, M = -x / den
        for k, j in enumerate(cols):
            m[j, :] = sp.Matrix([[gens.fraction(-e, den, domain) for e in x.to_list()[k]]])
        if not exact:
            slip = (b * den - block * x).to_list()  # (A_a den - A_na x) / den = A_na M + A_a
            for k, i in enumerate(rows):
                residual[i, :] = sp.Matrix([[gens.fraction(e, den, domain) for e in slip[k]]])
    if not exact:
        for i in set(all_rows) - covered:
            residual[i, :] = sp.Matrix([[gens.fraction(e, domain.one, domain) for e in a_a.to_list()[i]]])
    return m, residual

"""The Python example of docs/symbolic-and-codegen.md runs and its comments are its results: the (4.80)/(4.81) row and
the (4.84) substitution are read from the page (sympy notation with implicit products and ``^``) and compared with
what the code returns, entry by entry and symbolically. No test ran this page's example."""

from __future__ import annotations

import re
from pathlib import Path

import sympy as sp
from sympy.parsing.sympy_parser import (
    convert_xor,
    implicit_multiplication_application,
    parse_expr,
    standard_transformations,
)

DOC = Path(__file__).resolve().parents[2] / "docs" / "symbolic-and-codegen.md"
READ = (*standard_transformations, implicit_multiplication_application, convert_xor)


def _comment_list(block: str, code: str, names: dict) -> list[sp.Expr]:
    """The ``[a, b, ...]`` of the comment on the line of `block` that starts with `code` (a comment may name
    what it is first: ``# (4.84): [...]``)."""
    line = next(ln for ln in block.splitlines() if ln.startswith(code))
    entries = re.search(r"#[^\[]*\[(.*)\]\s*$", line)[1]
    return [parse_expr(e, local_dict=names, transformations=READ) for e in re.split(r",\s*(?![^()]*\))", entries)]


def test_the_symbolic_example_prints_what_its_comments_say():
    block = re.findall(r"```python\n(.*?)```", DOC.read_text(), flags=re.S)[0]
    scope: dict = {}
    exec(compile(block, str(DOC), "exec"), scope)  # our own documentation, not user text
    m, ext, b3, l3, om, vy = (scope[k] for k in ("m", "ext", "b3", "l3", "om", "vy"))
    sub = ext.substitute({b3: sp.atan2(-l3 * om, vy)})  # the block's last line, whose value it shows
    names = {"r": scope["r"], "l12": scope["l12"], "l3": l3, "vy": vy, "b3": b3, "om": om}
    assert m.exact is True and not ext.exact
    assert m.solved == ("vx", "vy", "omega", "w1.spin", "w2.spin")
    shown = _comment_list(block, "m.matrix", names)
    assert len(shown) == len(m.matrix)
    assert all(sp.simplify(a - b) == 0 for a, b in zip(shown, m.matrix, strict=True)), (shown, m.matrix)
    shown = _comment_list(block, "ext.substitute", names)
    assert len(shown) == len(sub)
    assert all(sp.simplify(a - b) == 0 for a, b in zip(shown, sub, strict=True)), (shown, sub)

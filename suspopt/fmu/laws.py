"""The semi-active control laws in C, translated from their own rules (:mod:`suspopt.control.laws`).

Each :class:`~suspopt.control.laws.Law` is a ``rule`` (its condition ``X``) and, for a
continuous law, a ``stiff_rule`` (its stiff coefficient), written with arithmetic, comparisons,
``np.where`` and ``np.clip`` only, so that the compiled engine runs the same functions. Their
Python source is translated here, statement for statement, into C functions of doubles:
one definition of every law, as the compiled engine has. A rule that uses anything else (a
law added later with a construct this translator does not know) cannot be exported, and
:func:`law_functions` says which law and why in one line, rather than write an FMU whose
controller is wrong.
"""

from __future__ import annotations

import ast
import inspect
import textwrap

from ..control.laws import LAWS, PARAMETERS
from ..errors import ConfigError

__all__ = ["law_functions", "c_name"]

_BINARY = {ast.Add: "+", ast.Sub: "-", ast.Mult: "*", ast.Div: "/"}
_COMPARE = {ast.Lt: "<", ast.LtE: "<=", ast.Gt: ">", ast.GtE: ">=", ast.Eq: "==", ast.NotEq: "!="}
#: numpy functions of the rules -> C helpers of the runtime (NaN as numpy treats it)
_CALLS = {"where": "su_where", "clip": "su_clip", "abs": "fabs", "sqrt": "sqrt"}


class _Untranslatable(Exception):
    """A construct the translator does not know."""


def c_name(law: str, part: str) -> str:
    """The C function of ``law``'s ``part`` (``x``: its condition, ``stiff``: its stiff
    coefficient)."""
    return f"su_law_{law}_{part}"


def _expr(node: ast.AST, names: set[str]) -> str:
    """C for the expression ``node`` over the doubles ``names``."""
    if isinstance(node, ast.Constant) and isinstance(node.value, (int, float)):
        if isinstance(node.value, bool):
            raise _Untranslatable("a boolean constant")
        return f"({float(node.value)!r})"
    if isinstance(node, ast.Name):
        if node.id not in names:
            raise _Untranslatable(f"the name {node.id!r}")
        return node.id
    if isinstance(node, ast.BinOp) and type(node.op) in _BINARY:
        return f"({_expr(node.left, names)} {_BINARY[type(node.op)]} {_expr(node.right, names)})"
    if isinstance(node, ast.UnaryOp) and isinstance(node.op, ast.USub):
        return f"(-{_expr(node.operand, names)})"
    if isinstance(node, ast.Compare) and len(node.ops) == 1 and type(node.ops[0]) in _COMPARE:
        op = _COMPARE[type(node.ops[0])]
        return f"(double)({_expr(node.left, names)} {op} {_expr(node.comparators[0], names)})"
    if isinstance(node, ast.Call) and not node.keywords:
        func = node.func
        if (
            isinstance(func, ast.Attribute)
            and isinstance(func.value, ast.Name)
            and func.value.id == "np"
            and func.attr in _CALLS
        ):
            return f"{_CALLS[func.attr]}({', '.join(_expr(a, names) for a in node.args)})"
    raise _Untranslatable(ast.dump(node)[:60])


def _function(rule, name: str) -> str:
    """The C function ``name`` of the Python ``rule`` (module docstring)."""
    tree = ast.parse(textwrap.dedent(inspect.getsource(rule)))
    fn = tree.body[0]
    if not isinstance(fn, ast.FunctionDef) or fn.args.vararg or fn.args.kwarg:
        raise _Untranslatable("its signature")
    args = [a.arg for a in fn.args.args]
    names, lines = set(args), []
    body = fn.body
    if body and isinstance(body[0], ast.Expr) and isinstance(body[0].value, ast.Constant):
        body = body[1:]  # (the docstring)
    for stmt in body:
        if (
            isinstance(stmt, ast.Assign)
            and len(stmt.targets) == 1
            and isinstance(stmt.targets[0], ast.Name)
        ):
            target = stmt.targets[0].id
            lines.append(f"    double {target} = {_expr(stmt.value, names)};")
            names.add(target)
        elif isinstance(stmt, ast.Return) and stmt.value is not None:
            lines.append(f"    return {_expr(stmt.value, names)};")
        else:
            raise _Untranslatable(type(stmt).__name__)
    if not lines or not lines[-1].lstrip().startswith("return"):
        raise _Untranslatable("a rule without a final return")
    params = ", ".join(f"double {a}" for a in args)
    unused = "".join(f"    (void){a};\n" for a in args)
    return f"static double {name}({params})\n{{\n{unused}" + "\n".join(lines) + "\n}\n"


def law_functions(names) -> str:
    """C source of the rules of the laws ``names``; ConfigError naming the first law whose
    rule cannot be translated."""
    parts = []
    for law in names:
        spec = LAWS[law]
        try:
            parts.append(_function(spec.rule, c_name(law, "x")))
            if spec.stiff_rule is not None:
                parts.append(_function(spec.stiff_rule, c_name(law, "stiff")))
        except (_Untranslatable, OSError, TypeError, SyntaxError) as exc:
            raise ConfigError(
                f"control law {law}: its rule cannot be exported to an FMU's C code ({exc})"
            ) from None
    return "\n".join(parts)


#: The law parameters in the order the rules take them after the motion.
PARAMETER_ORDER = tuple(PARAMETERS)

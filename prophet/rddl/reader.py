"""The entry points of reading: text or a file to checked blocks, text to an expression."""

from __future__ import annotations

from pathlib import Path

from alica.prophet.rddl.ast import Domain, Expr, NonFluents, RddlFile
from alica.prophet.rddl.check import check_domain, check_instance, check_non_fluents
from alica.prophet.rddl.errors import RddlError
from alica.prophet.rddl.expressions import Cursor
from alica.prophet.rddl.lexer import EOF, tokenize
from alica.prophet.rddl.parser import parse_blocks
from alica.source import byte_place


def parse_rddl(
    text: str, filename: str = "<string>", *, domain: Domain | None = None, non_fluents: NonFluents | None = None
) -> RddlFile:
    """Read and check the ``domain``, ``non-fluents`` and ``instance`` blocks of an RDDL text.

    The names used in the blocks are checked against the declarations: the
    domain's own, and for the other blocks those of the domain in the same
    text or else ``domain`` (and likewise the objects of ``non_fluents``).

    Args:
        text: the RDDL text.
        filename: the file name messages show.
        domain: the domain of the text's other blocks, when the text holds none.
        non_fluents: the non-fluents block of the text's instance, when the text holds none.

    Returns:
        The blocks found, each None when the text holds none.

    Raises:
        RddlError: ``FILE:LINE:COL: error: ... (fix: ...)`` at the first problem.
    """
    blocks = parse_blocks(text, filename)
    try:
        if blocks.domain is not None:
            check_domain(blocks.domain, filename)
        known_domain = blocks.domain or domain
        if blocks.non_fluents is not None:
            check_non_fluents(blocks.non_fluents, known_domain, filename)
        if blocks.instance is not None:
            check_instance(blocks.instance, known_domain, blocks.non_fluents or non_fluents, filename)
    except RecursionError:  # pragma: no cover - the reader gives up first
        raise RddlError(f"{filename}: an expression is nested too deeply to check", None, "split it") from None
    return blocks


def read_rddl(path: str | Path, *, domain: Domain | None = None, non_fluents: NonFluents | None = None) -> RddlFile:
    """Read and check an RDDL file (see :func:`parse_rddl`).

    Args:
        path: the file, UTF-8 text.
        domain: the domain of the file's other blocks, when the file holds none.
        non_fluents: the non-fluents block of the file's instance, when the file holds none.

    Returns:
        The blocks found.

    Raises:
        RddlError: the file cannot be read, is not UTF-8, or is no valid RDDL.
    """
    try:
        data = Path(path).read_bytes()
    except (OSError, ValueError) as error:  # ValueError: a NUL byte in the path
        raise RddlError(f"cannot read {path}: {error}", None, "check the path and its permissions") from error
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as error:
        place = byte_place(data, error.start, str(path))
        raise RddlError(
            f"the file is not UTF-8 text (byte 0x{data[error.start]:02x})", place, "save it as UTF-8"
        ) from error
    return parse_rddl(text, str(path), domain=domain, non_fluents=non_fluents)


def parse_expr(text: str, filename: str = "<string>") -> Expr:
    """Read one RDDL expression (unchecked: its names are not looked up).

    Args:
        text: the expression, such as ``sum_{?x : t} [f(?x)] <= 1``.
        filename: the file name messages show.

    Returns:
        The expression.

    Raises:
        RddlError: the text is no single expression.
    """
    cursor = Cursor(tokenize(text, filename), filename)
    try:
        expr = cursor.expr()
    except RecursionError:
        raise cursor.too_deep() from None
    token = cursor.peek()
    if token.kind != EOF:
        raise cursor.error(token, f"unexpected {token.shown()} after the expression", "remove it or add an operator")
    return expr

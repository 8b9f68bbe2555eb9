"""Lines of G-code made from arrays at once: the text Python's `fmt % values` writes, one line per row, for a
format whose conversions are all `%.<p>f`, built as bytes with numpy (no Python per number).

Each line is laid out as fixed-width columns of bytes (the format's literal text, then per number a sign, the
integer digits, the point and the decimals) with a mask of the bytes it keeps (no leading zeros, a sign only
when negative); the kept bytes in row order are the text. The rounding is printf's: the decimal nearest the
double's exact value, a tie to even. `|x| * 10**p` as a double can only land on the wrong side of a half when it
lies within a few ulps of one: those few numbers are formatted by Python and read back.
"""
from __future__ import annotations

import re
from typing import Optional

import numpy as np

_CONVERSION = re.compile(r"%\.(\d)f")
_MAX_SCALED = 1e14   # |x| * 10**p below it: the rounding check below holds and the digits fit int64


def _rounded(a: np.ndarray, p: int) -> Optional[np.ndarray]:
    """round(|x| * 10**p) as printf rounds the double |x| to p decimals (int64); None when out of range."""
    y = a * float(10 ** p)
    if not (y < _MAX_SCALED).all():
        return None
    r = np.rint(y)
    near_half = np.abs(y - np.floor(y) - 0.5) <= y * 1e-15 + 1e-9
    for i in np.flatnonzero(near_half):   # printf decides from the exact value
        r[i] = float(("%.*f" % (p, a[i])).replace(".", ""))
    return r.astype(np.int64)


def _number(x: np.ndarray, p: int) -> Optional[tuple[np.ndarray, np.ndarray]]:
    """The bytes (n, w) and kept mask of `'%.<p>f' % x` per value, or None when some cannot be done here."""
    r = _rounded(np.abs(x), p)
    if r is None:
        return None
    scale = 10 ** p
    whole, frac = r // scale, r % scale
    width = len(str(int(whole.max()))) if len(whole) else 1
    places = 10 ** np.arange(width - 1, -1, -1, dtype=np.int64)
    digits = (whole[:, None] // places) % 10
    shown = whole[:, None] >= places            # no leading zeros ...
    shown[:, -1] = True                         # ... but one digit always
    cols = [np.where(np.signbit(x), ord("-"), 0)[:, None], digits + ord("0")]
    keep = [np.signbit(x)[:, None], shown]
    if p:
        fplaces = 10 ** np.arange(p - 1, -1, -1, dtype=np.int64)
        cols += [np.full((len(x), 1), ord(".")), (frac[:, None] // fplaces) % 10 + ord("0")]
        keep += [np.ones((len(x), 1 + p), dtype=bool)]
    return np.hstack(cols).astype(np.uint8), np.hstack(keep)


def lines(fmt: str, values: np.ndarray) -> Optional[str]:
    """`fmt % tuple(row)` for every row of `values` (n, k), joined; None when `fmt` has a conversion other than
    `%.<p>f` (or `%%`), its count differs from k, or a value is not finite or too large: format it by Python."""
    literals = _CONVERSION.split(fmt)[::2]
    precisions = [int(p) for p in _CONVERSION.findall(fmt)]
    if any("%" in t for t in literals) or len(precisions) != values.shape[1] or not np.isfinite(values).all():
        return None
    n = len(values)
    cols, keep = [], []
    for k, text in enumerate(literals):
        if text:
            raw = np.frombuffer(text.encode("ascii"), dtype=np.uint8)
            cols.append(np.broadcast_to(raw, (n, len(raw))))
            keep.append(np.ones((n, len(raw)), dtype=bool))
        if k < len(precisions):
            number = _number(values[:, k], precisions[k])
            if number is None:
                return None
            cols.append(number[0])
            keep.append(number[1])
    if not cols:
        return ""
    return np.hstack(cols)[np.hstack(keep)].tobytes().decode("ascii")

"""A combo box that chooses one object of the document for a link property (the region's sketch, the 3D offset's
start curve): filled with candidates and '(none)', read back as the object or None."""
from __future__ import annotations

from typing import Any, Optional, Sequence

NONE = "(none)"


def edge_objects(doc: Any) -> list[Any]:
    """The document's objects with edges (tool bits and other Path resources left out)."""
    out = []
    for o in doc.Objects:
        if not hasattr(o, "Shape") or hasattr(o, "PathResource"):
            continue
        if not o.Shape.isNull() and o.Shape.Edges:
            out.append(o)
    return out


def fill(combo: Any, candidates: Sequence[Any], current: Optional[Any]) -> None:
    """The combo's items: '(none)' and the candidates' labels (their names as data), `current` selected."""
    combo.blockSignals(True)
    combo.clear()
    combo.addItem(NONE, "")
    for o in candidates:
        combo.addItem(o.Label, o.Name)
    index = combo.findData(current.Name) if current is not None else 0
    combo.setCurrentIndex(max(index, 0))
    combo.blockSignals(False)


def write(combo: Any, obj: Any, prop: str) -> None:
    """The chosen object into obj.<prop> (None for '(none)'), only when it changed."""
    name = combo.currentData()
    target = obj.Document.getObject(name) if name else None
    if getattr(obj, prop) != target:
        setattr(obj, prop, target)

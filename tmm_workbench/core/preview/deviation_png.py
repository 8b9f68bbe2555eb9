"""The simulated stock's deviation from the design as a heat map (PNG, matplotlib Agg): red where material
is left, blue where the design is gouged, a colour bar in mm, the numbers in the title. Cells without the
design under them are grey (the colours are core.preview.deviation_colours', as the GUI's). Where the neck,
shank or holder came too close to the stock (core.sim.stock_collisions), black crosses. matplotlib is imported
inside the function (no GUI backend on import)."""
from __future__ import annotations

from typing import TYPE_CHECKING, Optional

import numpy as np

if TYPE_CHECKING:
    from tmm_workbench.core.sim.compare import Comparison
    from tmm_workbench.core.sim.grid import Grid
    from tmm_workbench.core.sim.stock_collisions import StockCollisions

COLLISION_LABEL = "holder/shank collision"


def render_deviation_png(comparison: "Comparison", grid: "Grid", path: str, title: str = "",
                         dpi: int = 110, collisions: Optional["StockCollisions"] = None) -> str:
    import matplotlib
    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt
    from matplotlib.colors import TwoSlopeNorm

    from tmm_workbench.core.preview.deviation_colours import NO_DESIGN_HEX, cmap as rdbu, colour_range

    dev = comparison.deviation
    o = comparison.overall
    tol = comparison.tolerance
    low, high = colour_range(dev, tol)
    cmap = rdbu().copy()
    cmap.set_bad(NO_DESIGN_HEX)
    fig, ax = plt.subplots(figsize=(7.2, 6.0), dpi=dpi)
    x0, x1, y0, y1 = grid.extent
    im = ax.imshow(np.ma.masked_invalid(dev), origin="lower", extent=(x0, x1, y0, y1), cmap=cmap,
                   norm=TwoSlopeNorm(vmin=low, vcenter=0.0, vmax=high), interpolation="nearest")
    bar = fig.colorbar(im, ax=ax, shrink=0.85)
    bar.set_label("deviation from the design, mm (vertical; + material left, - gouge)")
    ax.set_xlabel("x mm")
    ax.set_ylabel("y mm")
    ax.set_aspect("equal")
    if collisions is not None and collisions.count:
        xy = collisions.positions[:, :2]
        ax.scatter(xy[:, 0], xy[:, 1], marker="x", c="black", s=36, linewidths=1.4, zorder=3,
                   label=f"{COLLISION_LABEL} ({collisions.count:,})")
        ax.set_xlim(x0, x1)
        ax.set_ylim(y0, y1)
        ax.legend(loc="upper right", fontsize=7, framealpha=0.85)
    verdict = f"GOUGE in {o.gouge_cells} cells" if o.gouge_cells else "no gouge"
    ax.set_title(f"{title}\nmax left {o.max_left:.4f} mm, min {o.min_deviation:.4f} mm, "
                 f"p95 {o.percentiles.get(95, 0.0):.4f} mm; {verdict} (tolerance {tol:g} mm)\n"
                 f"removed {comparison.removed_volume / 1000:.2f} cm3, left {o.remaining_volume / 1000:.3f} cm3, "
                 f"cell {grid.cell:g} mm", fontsize=8)
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)
    return path

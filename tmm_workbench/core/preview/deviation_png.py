"""The simulated stock's deviation from the design as a heat map (PNG, matplotlib Agg): red where material
is left, blue where the design is gouged, a colour bar in mm, the numbers in the title. With a colour band (as
TMM Simulate's: +-band mm, the tolerance by default there) the colours span the band and the cells beyond it take
its darkest ends, counted in the title; without one, the whole range. Cells without the design under them are grey (the colours are core.preview.deviation_colours', as the GUI's). Where the neck,
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
                         dpi: int = 110, collisions: Optional["StockCollisions"] = None,
                         band: Optional[float] = None) -> str:
    import matplotlib
    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt
    from matplotlib.colors import TwoSlopeNorm

    from tmm_workbench.core.preview.deviation_colours import (NO_DESIGN_HEX, band_colours, beyond_band,
                                                              cmap as rdbu, colour_range)

    dev = comparison.deviation
    o = comparison.overall
    tol = comparison.tolerance
    fig, ax = plt.subplots(figsize=(7.2, 6.0), dpi=dpi)
    x0, x1, y0, y1 = grid.extent
    beyond = ""
    if band is None:
        low, high = colour_range(dev, tol)
        cmap = rdbu().copy()
        cmap.set_bad(NO_DESIGN_HEX)
        im = ax.imshow(np.ma.masked_invalid(dev), origin="lower", extent=(x0, x1, y0, y1), cmap=cmap,
                       norm=TwoSlopeNorm(vmin=low, vcenter=0.0, vmax=high), interpolation="nearest")
        bar = fig.colorbar(im, ax=ax, shrink=0.85)
    else:
        from matplotlib.cm import ScalarMappable
        from matplotlib.colors import LinearSegmentedColormap, Normalize

        ax.imshow(band_colours(dev, band).reshape(dev.shape + (3,)), origin="lower", extent=(x0, x1, y0, y1),
                  interpolation="nearest")
        inside = LinearSegmentedColormap.from_list("band", rdbu()(np.linspace(0.1, 0.9, 256)))
        inside.set_under(rdbu()(0.0))
        inside.set_over(rdbu()(1.0))
        bar = fig.colorbar(ScalarMappable(Normalize(-band, band), inside), ax=ax, shrink=0.85, extend="both")
        above, below, hi, lo = beyond_band(dev, band)
        beyond = f"; beyond +-{band:g} mm: {above} cells above (to {hi:+.4f}), {below} below (to {lo:+.4f})"
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
                 f"cell {grid.cell:g} mm{beyond}", fontsize=8)
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)
    return path

"""The simulated stock in the 3D view: a Coin quad mesh coloured by deviation (core.preview
.deviation_colours), a node of the view's scene graph (never a document object), named so tests and users
find it. The cells where the neck, shank or holder came too close to the stock are red markers inside the
stock's node: they show and hide with it."""
from __future__ import annotations

from typing import Any

import numpy as np

from tmm_workbench.core.preview.deviation_colours import band_colours, block_centres, decimate

NODE_NAME = "TmmSimulatedStock"
COLLISIONS_NAME = "TmmStockCollisions"
COLLISION_RGB = (0.9, 0.0, 0.0)


def stock_node(grid: Any, heights: np.ndarray, deviation: np.ndarray, tolerance: float,
               band: float) -> tuple[Any, int]:
    """A SoSeparator holding the simulated stock as a quad mesh with per-vertex colours (a colour band of
    +-`band` mm, the cells beyond it darkest), and the block size of the decimation."""
    from pivy import coin

    h, d, b = decimate(np.asarray(heights, dtype=float), np.asarray(deviation, dtype=float), tolerance)
    X, Y = np.meshgrid(block_centres(grid.x0, grid.cell, grid.nx, b),
                       block_centres(grid.y0, grid.cell, grid.ny, b))
    points = np.column_stack([X.ravel(), Y.ravel(), h.ravel()])
    root = coin.SoSeparator()
    root.setName(NODE_NAME)
    hints = coin.SoShapeHints()  # lit from both sides: walls seen from below are not black
    hints.vertexOrdering = coin.SoShapeHints.COUNTERCLOCKWISE
    hints.shapeType = coin.SoShapeHints.UNKNOWN_SHAPE_TYPE
    coords = coin.SoCoordinate3()
    coords.point.setValues(0, len(points), points.tolist())
    material = coin.SoMaterial()
    material.diffuseColor.setValues(0, len(points), band_colours(d, band).tolist())
    binding = coin.SoMaterialBinding()
    # a quad mesh is not indexed: Coin reads PER_VERTEX_INDEXED as PER_VERTEX there, so say what it is
    binding.value = coin.SoMaterialBinding.PER_VERTEX
    mesh = coin.SoQuadMesh()
    mesh.verticesPerRow = h.shape[1]
    mesh.verticesPerColumn = h.shape[0]
    for child in (hints, coords, material, binding, mesh):
        root.addChild(child)
    return root, b


def collision_node(positions: np.ndarray) -> Any:
    """A SoSeparator named COLLISIONS_NAME with a red cross marker at each (x, y, z) of `positions` (the cells of
    core.sim.stock_collisions), drawn over the stock."""
    from pivy import coin

    pts = np.asarray(positions, dtype=float).reshape(-1, 3)
    root = coin.SoSeparator()
    root.setName(COLLISIONS_NAME)
    material = coin.SoMaterial()
    material.diffuseColor.setValue(*COLLISION_RGB)
    material.emissiveColor.setValue(*COLLISION_RGB)
    binding = coin.SoMaterialBinding()  # one colour: not the stock's per-vertex binding this node inherits
    binding.value = coin.SoMaterialBinding.OVERALL
    coords = coin.SoCoordinate3()
    coords.point.setValues(0, len(pts), pts.tolist())
    markers = coin.SoMarkerSet()
    markers.markerIndex = coin.SoMarkerSet.CROSS_9_9
    markers.numPoints = len(pts)
    for child in (material, binding, coords, markers):
        root.addChild(child)
    return root


def find_node(scene: Any, name: str = NODE_NAME) -> bool:
    """Whether a node named `name` is in the scene graph."""
    from pivy import coin

    search = coin.SoSearchAction()
    search.setName(coin.SbName(name))
    search.setInterest(coin.SoSearchAction.FIRST)
    search.setSearchingAll(True)
    search.apply(scene)
    return search.getPath() is not None

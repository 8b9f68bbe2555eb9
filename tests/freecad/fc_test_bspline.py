"""FreeCAD's B-spline and Bézier surfaces taken exactly: TMM's Bézier split (knot insertion) evaluated by the
kernel against OCC's own evaluation (Part.BSplineSurface.value / normal, Part.BezierSurface.value)."""
from __future__ import annotations

import unittest

import FreeCAD
import numpy as np
import Part

from tmm_workbench.app import geometry
from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.strategies.multipoint import BezierFace, position_points

V = FreeCAD.Vector


def bspline(periodic: bool = False, rational: bool = False) -> Part.BSplineSurface:
    """Bicubic x biquadratic with uneven knots and a double knot in u."""
    uknots, umults = [0.0, 0.3, 0.5, 1.2, 2.0], [4, 1, 2, 1, 4]
    vknots, vmults = [0.0, 1.0, 2.5, 3.0], [3, 1, 1, 3]
    nu, nv = sum(umults) - 4, sum(vmults) - 3
    rng = np.random.default_rng(4)
    poles = [[V(12.0 * i, 9.0 * j, float(rng.uniform(-3, 3))) for j in range(nv)] for i in range(nu)]
    weights = [[1.0 + (0.5 if rational and (i, j) == (2, 1) else 0.0) for j in range(nv)] for i in range(nu)]
    s = Part.BSplineSurface()
    s.buildFromPolesMultsKnots(poles, umults, vmults, uknots, vknots, False, False, 3, 2, weights)
    if periodic:
        s.setUPeriodic()
    return s


class BsplineExact(unittest.TestCase):
    def compare(self, s, face: BezierFace) -> None:
        u0, u1, v0, v1 = s.bounds()
        self.assertEqual(face.domain, (u0, u1, v0, v1))
        uv = np.array([(u, v) for u in np.linspace(u0, u1, 23) for v in np.linspace(v0, v1, 19)])
        got = face.evaluate(uv)
        ref = np.array([tuple(s.value(u, v)) for u, v in uv])
        np.testing.assert_allclose(got["S"], ref, atol=1e-9)
        n = np.cross(got["Su"], got["Sv"])
        n /= np.linalg.norm(n, axis=1)[:, None]
        nref = np.array([tuple(s.normal(u, v)) for u, v in uv])
        np.testing.assert_allclose(np.abs((n * nref).sum(1)), 1.0, atol=1e-9)

    def test_bspline_surface(self) -> None:
        s = bspline()
        face = geometry.bezier_face(s)
        self.assertEqual((face.native.nu, face.native.nv), (4, 3))
        self.compare(s, face)

    def test_periodic_bspline_made_non_periodic(self) -> None:
        s = bspline(periodic=True)
        self.assertTrue(s.isUPeriodic())
        face = geometry.bezier_face(s)
        self.compare(s, face)

    def test_rational_bspline_refused(self) -> None:
        with self.assertRaisesRegex(TmmError, "rational"):
            geometry.bezier_face(bspline(rational=True))

    def test_bezier_surface_and_positioning(self) -> None:
        z = [80, 70, 70, 80, 70, 55, 55, 70, 70, 55, 55, 70, 80, 70, 70, 80]
        b = Part.BezierSurface()
        b.increase(3, 3)
        for i in range(4):
            for j in range(4):
                b.setPole(i + 1, j + 1, V(50.0 * i, 50.0 * j, float(z[4 * i + j])))
        face = geometry.bezier_face(b)
        self.compare(b, face)
        res = position_points(face, 6.7, 6.0, np.array([[75.0, 75.0], [40.0, 110.0]]))
        self.assertTrue((res.status != 2).all(), res.reason_texts())
        self.assertEqual(res.status[0], 0, res.reason_texts())
        # Contacts on OCC's surface: the face's point at the contact's parameters is OCC's point.
        for k in ("P", "Q"):
            uv = res["uv" + k]
            for i in range(len(uv)):
                self.assertLess((V(*res[k][i]) - b.value(*uv[i])).Length, 1e-9)


if __name__ == "__main__":
    unittest.main()

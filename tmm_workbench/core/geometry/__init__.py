"""Geometry the strategies machine: triangle meshes (TriMesh, STL), Bezier faces (BezierFace), B-spline to Bezier."""

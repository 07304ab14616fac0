"""Geometry: the data types of surfaces, meshes, nets and strips, and the math on them.

- :mod:`.grid`: rows / columns of a structured quad mesh as index arrays
- :mod:`.quadmesh`: QuadMesh (V (n,3), F (m,4)) over OpenMesh; TriMesh for targets
- :mod:`.meshfile`, :mod:`.objplain`: mesh files (OBJ, PLY, OFF; float64 exact), polylines
- :mod:`.bspline`: BSplineSurface, basis matrices (eq. 4.1), fits, JSON io
- :mod:`.diffgeo`: fundamental forms, K, H, principal curvatures (eqs. 4.2-4.6)
- :mod:`.fit`: least-squares line, plane and circle of point sets
- :mod:`.vectors`, :mod:`.spline_batch`: rows of 3-vectors; many cubic splines at once
- :mod:`.net`: Net (joints, loops, lamellae) and Lamella
- :mod:`.strips3d`: the strip as built (material frame, width, thickness)
- :mod:`.igl_adapter`: the only module that calls libigl
- :mod:`.rhino_adapter`: the only module that imports rhino3dm: Rhino meshes as double-precision
  arrays (polygons as Rhino keeps them), NURBS surfaces as B-splines exactly and back, curves,
  .3dm files (the reader, the server and the export all go through it)

May import: :mod:`gridshell.core`, :mod:`gridshell.solver`.
"""

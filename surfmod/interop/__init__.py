"""Exchange of B-spline/NURBS curves and surfaces with the Python NURBS ecosystem:
geomdl (NURBS-Python), splipy and rhino3dm (OpenNURBS, ``.3dm`` files).

The libraries are optional (``pip install surfmod[interop]``); each converter imports
its library on use and names the extra when it is missing.  Degrees, full knot vectors
and weights are copied exactly; the libraries keep rational control points in
homogeneous form ``(w x, w y, w z, w)``, so a rational net read back is the exact
quotient of those numbers (equal to the original to the last bit or one unit in the last
place), a polynomial net is bit-identical.
"""

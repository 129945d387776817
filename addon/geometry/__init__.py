"""Geometry: the lat-long mapping, the proxy mesh, ray casting, patches and lattices on it,
clusters of a detailed object's triangles, and the rectified raster of a plane."""

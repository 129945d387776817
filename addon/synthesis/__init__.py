"""Texture synthesis: the order-independent multi-resolution fill of an image (`texture`) and
the fill of a hidden plane's reflectance on its rectified raster (`plane_fill`)."""

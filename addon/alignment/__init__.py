"""Align to Photo: the proxy's pose on its support fitted to the object's outline in the panorama."""

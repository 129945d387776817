"""Match Room: the room's floor, walls and ceiling from a dozen clicks in the panorama.

The artist clicks the floor's corners in the lat-long panorama (pixel coordinates), gives the
camera height or one known length, and optionally one point where a wall meets the ceiling;
`fit.fit_room` turns the clicks into a floor polygon around the probe centre whose corners
reproject onto the clicks, `meshes.room_meshes` into the Floor, Walls and Ceiling proxies.
numpy only: the Blender side (addon/blender/room_builder.py) builds the meshes.
"""

"""The 3D view: MJCF geoms as viser nodes posed every frame, force arrows and their labels,
the trail of a point, the camera, and where labels go on the screen.
"""

"""What one browser sees: the 3D scene, arrows, panels and messages of a session
(:mod:`.browser`), and the folder « Partager » that sets that view from a link.
"""

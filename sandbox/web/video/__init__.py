"""Videos of a recording for slides (``sandbox replay FILE --video``) and the page's folder
« Vidéo »: options checked first, MuJoCo's offscreen renderer, the arrows and readouts
written over each frame, the strip of readouts; drawn in a worker process.
"""

"""The core renderer: views as RGB images with a depth buffer (no textual).

``raster`` splats voxels and draws overlays, ``framing`` fits a camera to a
box, ``output`` colours a run's output by what each voxel is; the colour
maps and the contrast measure are ``ladartui.colour`` (views use them too).
"""

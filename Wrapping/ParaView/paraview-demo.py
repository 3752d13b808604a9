"""ParaView demo of the PenumbraShadows plugin: an isosurface over a ground plane, lit by one
sun-like directional light, rendered headless by pvbatch to a PNG.

    pvbatch --disable-xdisplay-test paraview-demo.py OUT.png [TECHNIQUE]

The plugin is found through PV_PLUGIN_PATH (./penumbra.sh paraview sets it up).
"""
import sys

from paraview.simple import (AddLight, Contour, CreateView, Plane, Render,
                             SaveScreenshot, Show, Wavelet)

out = sys.argv[1] if len(sys.argv) > 1 else "paraview-demo.png"
technique = sys.argv[2] if len(sys.argv) > 2 else None

view = CreateView("PenumbraShadowView")
if technique:
    view.ShadowTechnique = technique
view.ViewSize = [800, 600]
view.OrientationAxesVisibility = 0
view.Background = [0.32, 0.34, 0.43]
# One sun-like light, so that the shadows read clearly; the light kit (5 lights) would give
# five faint shadows.
view.UseLight = 0
sun = AddLight(view=view)
sun.Coords = "Scene"
sun.Type = "Directional"
sun.Position = [-10.0, -6.0, 25.0]
sun.FocalPoint = [0.0, 0.0, 0.0]
sun.Intensity = 1.0

# Wavelet's scalar field, isosurfaced: a blobby surface over [-10, 10]^3.
iso = Contour(Input=Wavelet(), ContourBy=["POINTS", "RTData"], Isosurfaces=[190.0])
iso_display = Show(iso, view)
iso_display.DiffuseColor = [0.85, 0.55, 0.35]
iso_display.AmbientColor = [0.85, 0.55, 0.35]
iso_display.ColorArrayName = ["POINTS", ""]
iso_display.Ambient = 0.25

ground = Plane(Origin=[-22.0, -22.0, -11.0], Point1=[22.0, -22.0, -11.0],
               Point2=[-22.0, 22.0, -11.0])
ground_display = Show(ground, view)
ground_display.DiffuseColor = [0.72, 0.72, 0.7]
ground_display.AmbientColor = [0.72, 0.72, 0.7]
ground_display.Ambient = 0.25

view.CameraPosition = [38.0, -52.0, 34.0]
view.CameraFocalPoint = [0.0, 0.0, -4.0]
view.CameraViewUp = [0.0, 0.0, 1.0]
Render(view)
SaveScreenshot(out, view, ImageResolution=[800, 600])
view.UpdatePropertyInformation()
print("paraview-demo: wrote %s with technique %s" %
      (out, view.GetProperty("InstalledShadowTechnique").GetData()))

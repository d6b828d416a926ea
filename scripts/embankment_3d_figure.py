"""The figure of cases/embankment_3d.toml: its material points at the end of the run, coloured by
their settlement, seen from above the end slope.

Run with pvbatch (headless) on a run's output directory:
    porompm run cases/embankment_3d.toml --out out/embankment_3d
    pvbatch scripts/embankment_3d_figure.py out/embankment_3d docs/figures/embankment_3d.png
"""
import sys

from paraview import servermanager as sm
from paraview import simple as pvs

out, png = sys.argv[1], sys.argv[2]
reader = pvs.XDMFReader(FileNames=[out + "/fields.xdmf"])
times = list(reader.TimestepValues)
reader.UpdatePipeline(times[-1])
# The particles' block of the last frame (named `particles[<frame>]`).
data = sm.Fetch(reader)
it = data.NewIterator()
it.InitTraversal()
while not it.GetCurrentMetaData().Get(data.NAME()).startswith("particles"):
    it.GoToNextItem()
points = pvs.TrivialProducer()
points.GetClientSideObject().SetOutput(it.GetCurrentDataObject())
view = pvs.GetActiveViewOrCreate("RenderView")
view.ViewSize = [1400, 900]
view.Background = [1.0, 1.0, 1.0]
view.OrientationAxesVisibility = 1
settlement = pvs.Calculator(Input=points, ResultArrayName="settlement_mm", Function="-1000*displacement_Y")
shown = pvs.Show(settlement, view)
shown.SetRepresentationType("Points")
shown.PointSize = 3
pvs.ColorBy(shown, ("POINTS", "settlement_mm"))
lut = pvs.GetColorTransferFunction("settlement_mm")
lut.ApplyPreset("Viridis (matplotlib)", True)
shown.SetScalarBarVisibility(view, True)
bar = pvs.GetScalarBar(lut, view)
bar.Title = "settlement [mm]"
bar.ComponentTitle = ""
bar.TitleColor = [0, 0, 0]
bar.LabelColor = [0, 0, 0]
view.CameraPosition = [17.0, 11.0, 19.0]
view.CameraFocalPoint = [3.0, 1.5, 3.5]
view.CameraViewUp = [0.0, 1.0, 0.0]
pvs.Render(view)
pvs.SaveScreenshot(png, view, ImageResolution=[1400, 900])

"""One off-screen scene, made once and drawn again for every frame of a run.

The body is one VTK grid whose points (X + u, m) and colour values are overwritten in
place at each frame; a pipeline of VTK filters takes the eroded cells out (a threshold
on the cells' ``live`` flag), cuts the body open (a clip by a plane, which keeps the
cell values on the cut face) and extracts the visible surface. The walls, the loose
nodes (drawn as points), the time label and the colour bar are actors of the same
scene. A frame costs one render and one read of the picture; the window, its OpenGL
context and shaders are made once. An empty body (every cell eroded) is drawn as
nothing but its loose nodes. This module must not import DOLFINx (see
:mod:`rwall_fem.output.frames`).
"""

from __future__ import annotations

import os

os.environ.setdefault("VTK_DEFAULT_OPENGL_WINDOW", "vtkEGLRenderWindow")  # before VTK's window

import numpy as np
import vtkmodules.vtkRenderingFreeType  # noqa: F401  (the text)
import vtkmodules.vtkRenderingOpenGL2  # noqa: F401  (the window and mappers that draw)
from vtkmodules.util.numpy_support import numpy_to_vtk, numpy_to_vtkIdTypeArray, vtk_to_numpy
from vtkmodules.vtkCommonCore import vtkLookupTable, vtkPoints
from vtkmodules.vtkCommonDataModel import vtkCellArray, vtkPlane, vtkPolyData, vtkUnstructuredGrid
from vtkmodules.vtkFiltersCore import vtkThreshold
from vtkmodules.vtkFiltersGeneral import vtkTableBasedClipDataSet
from vtkmodules.vtkFiltersGeometry import vtkGeometryFilter
from vtkmodules.vtkRenderingAnnotation import vtkScalarBarActor
from vtkmodules.vtkRenderingCore import (
    vtkActor,
    vtkLightKit,
    vtkPolyDataMapper,
    vtkRenderer,
    vtkRenderWindow,
    vtkTextActor,
    vtkWindowToImageFilter,
)

from rwall_fem.output.coloring import colour_table, rgb

__all__ = ["Picture", "polydata"]

# VTK's classes are imported one module each (``import vtk`` loads every module: 1 s), and
# pyvista not at all: its plotting imports matplotlib's pyplot (0.5 s of a 2 s drawing).
BAR = (0.2, 0.06, 0.6, 0.04)  # the colour bar's box: x, y, width, height (of the window)
WALL_COLOR = "#a9b4c2"  # a cool grey that no colour map uses
LOOSE_COLOR = "#404040"
BACKGROUND = "#ffffff"
GHOST_OPACITY = 0.12


def polydata(points: np.ndarray, faces: np.ndarray | None = None) -> vtkPolyData:
    """VTK's surface of ``points`` ((n, 3), m) and ``faces`` (VTK's legacy cell array
    ``[k, i0, .., ik-1, k, ...]``), or of the points alone as vertices."""
    points = np.ascontiguousarray(points, dtype=float).reshape(-1, 3)
    data = vtkPolyData()
    vertices = vtkPoints()
    vertices.SetData(numpy_to_vtk(points, deep=True))
    data.SetPoints(vertices)
    if faces is None:
        faces = np.column_stack([np.ones(len(points), int), np.arange(len(points))]).ravel()
        cells, setter = vtkCellArray(), data.SetVerts
    else:
        cells, setter = vtkCellArray(), data.SetPolys
    cells.ImportLegacyFormat(numpy_to_vtkIdTypeArray(np.asarray(faces, np.int64), deep=True))
    setter(cells)
    return data


class Picture:
    """The scene of a run's frames: the body of ``mesh`` (dict of ``topology``,
    ``cell_types``, ``points``) coloured as ``paint`` says, seen by ``view``
    (:class:`rwall_fem.output.view.View`) in a window of ``size`` (w, h) pixels;
    ``erodes``: the frames hold ``cell_eroded``; ``cut``: (point, normal) of the plane
    whose normal side is removed, or None; ``ghost``: that side drawn translucent;
    ``edges``: the cell edges are drawn."""

    def __init__(self, mesh, paint, view, size, *, erodes, cut, ghost, edges):
        self.size = tuple(int(x) for x in size)
        self.paint, self.cut = paint, cut
        self.renderer = vtkRenderer()
        self.renderer.SetBackground(*rgb(BACKGROUND))
        vtkLightKit().AddLightsToRenderer(self.renderer)
        self.renderer.LightFollowCameraOn()
        self._window = vtkRenderWindow()
        self._window.SetOffScreenRendering(1)
        self._window.SetSize(*self.size)
        self._window.AddRenderer(self.renderer)
        self.points0 = np.asarray(mesh["points"], float)
        grid = vtkUnstructuredGrid()
        cells = vtkCellArray()
        cells.ImportLegacyFormat(numpy_to_vtkIdTypeArray(np.asarray(mesh["topology"], np.int64),
                                                         deep=True))  # fmt: skip
        self._types = np.ascontiguousarray(mesh["cell_types"], dtype=np.uint8)
        grid.SetCells(numpy_to_vtk(self._types, deep=True), cells)
        self._xyz = np.array(self.points0, dtype=float, order="C")
        grid.SetPoints(vtkPoints())
        grid.GetPoints().SetData(numpy_to_vtk(self._xyz, deep=False))
        n = grid.GetNumberOfCells() if paint.per_cell else grid.GetNumberOfPoints()
        self._values = np.zeros(n)
        colours = numpy_to_vtk(self._values, deep=False)
        colours.SetName("colour")
        data = grid.GetCellData() if paint.per_cell else grid.GetPointData()
        data.AddArray(colours)
        self._live = None
        self._filters: list = []  # held here: a VTK filter Python forgets is freed
        source = grid
        output = None
        if erodes:  # eroded cells are not drawn
            self._live = np.ones(grid.GetNumberOfCells())
            live = numpy_to_vtk(self._live, deep=False)
            live.SetName("live")
            grid.GetCellData().AddArray(live)
            threshold = vtkThreshold()
            threshold.SetInputData(grid)
            threshold.SetInputArrayToProcess(0, 0, 0, 1, "live")  # 1: cell data
            threshold.SetUpperThreshold(0.5)  # UPPER keeps the values >= it
            threshold.SetThresholdFunction(vtkThreshold.THRESHOLD_UPPER)
            output = threshold.GetOutputPort()
            self._filters.append(threshold)
        self.grid = grid
        self._lut = self._lookup_table()
        kept = self._surface(self._clipped(source, output, inside=True), opaque=True)
        kept.GetProperty().SetEdgeVisibility(bool(edges))
        if cut is not None and ghost:
            self._surface(self._clipped(source, output, inside=False), opaque=False)
        self._loose = vtkPolyData()
        self._actor(self._loose, LOOSE_COLOR).GetProperty().SetPointSize(3.0)
        self._walls: list = []
        self._surfaces: dict = {}  # the walls' surfaces drawn, by the id of theirs
        self._time = self._text(" ", 12, self.size[1] - 32, 12)  # in view.TIME_CORNER
        backing = self._time.GetTextProperty()  # legible over a body that fills the picture
        backing.SetBackgroundColor(*rgb(BACKGROUND))
        backing.SetBackgroundOpacity(0.8)
        self._colour_bar()
        view.apply(self.renderer)
        self._view = view
        # Multisampling costs 7 times the frame in Mesa's software renderer (150 ms, not
        # 20, for the bar demo at 800 x 600): none.
        self._window.SetMultiSamples(0)
        self._grab = vtkWindowToImageFilter()
        self._grab.SetInput(self._window)
        self._grab.ShouldRerenderOff()  # the frame was just rendered
        self._grab.SetInputBufferTypeToRGB()
        self._grab.ReadFrontBufferOff()

    # --- the pipeline -----------------------------------------------------------------

    def _clipped(self, grid, port, *, inside: bool):
        """The output port of the body (``grid``, or the filter's ``port``) cut by the plane:
        the side opposite the normal (``inside``) or the removed side."""
        if self.cut is None:
            return grid, port
        plane = vtkPlane()
        plane.SetOrigin(*self.cut[0])
        plane.SetNormal(*self.cut[1])
        clip = vtkTableBasedClipDataSet()
        if port is None:
            clip.SetInputData(grid)
        else:
            clip.SetInputConnection(port)
        clip.SetClipFunction(plane)
        clip.SetInsideOut(inside)  # inside: where the plane's function is negative
        self._filters += [plane, clip]
        return None, clip.GetOutputPort()

    def _surface(self, source, *, opaque: bool):
        grid, port = source
        surface = vtkGeometryFilter()
        if port is None:
            surface.SetInputData(grid)
        else:
            surface.SetInputConnection(port)
        mapper = vtkPolyDataMapper()
        mapper.SetInputConnection(surface.GetOutputPort())
        self._filters.append(surface)
        mapper.SetLookupTable(self._lut)
        mapper.SetScalarRange(*self.paint.clim)
        mapper.UseLookupTableScalarRangeOff()
        if self.paint.per_cell:
            mapper.SetScalarModeToUseCellFieldData()
        else:
            mapper.SetScalarModeToUsePointFieldData()
            mapper.InterpolateScalarsBeforeMappingOn()
        mapper.SelectColorArray("colour")
        mapper.ScalarVisibilityOn()
        actor = vtkActor()
        actor.SetMapper(mapper)
        prop = actor.GetProperty()
        prop.SetAmbient(0.3)
        prop.SetDiffuse(0.7)
        prop.SetEdgeColor(0.25, 0.25, 0.25)
        prop.SetLineWidth(0.5)
        if not opaque:
            prop.SetOpacity(GHOST_OPACITY)
        self.renderer.AddActor(actor)
        return actor

    def _actor(self, polydata, colour, opacity: float = 1.0):
        """An actor of one colour drawing ``polydata`` (vertices, or a surface)."""
        mapper = vtkPolyDataMapper()
        mapper.SetInputData(polydata)
        mapper.ScalarVisibilityOff()
        actor = vtkActor()
        actor.SetMapper(mapper)
        prop = actor.GetProperty()
        prop.SetColor(*rgb(colour))
        prop.SetAmbient(0.3)
        prop.SetDiffuse(0.7)
        prop.SetOpacity(opacity)
        self.renderer.AddActor(actor)
        return actor

    def _lookup_table(self):
        paint = self.paint
        table = colour_table(paint.cmap, len(paint.names) or 256)
        lut = vtkLookupTable()
        lut.SetNumberOfTableValues(len(table))
        for i, colour in enumerate(table):
            lut.SetTableValue(i, *colour, 1.0)
        lut.SetRange(*paint.clim)
        return lut

    # --- the frames ---------------------------------------------------------------------

    def set_walls(self, walls, surfaces) -> None:
        """The walls (shapes) and their ``surfaces`` (:class:`rwall_fem.output.view.Surface`)
        in this frame; flat walls seen from their allowed side are opaque, the others
        translucent with their outline."""
        if not self._walls:
            for wall in walls:
                behind = self._view.behind(wall)
                self._walls.append(self._actor(vtkPolyData(), WALL_COLOR, 1.0 if behind else 0.3))
        for actor, surface in zip(self._walls, surfaces, strict=True):
            drawn = self._surfaces.get(id(surface))
            if drawn is None:
                drawn = self._surfaces[id(surface)] = (surface, polydata(*surface))
            if actor.GetMapper().GetInput() is not drawn[1]:
                actor.GetMapper().SetInputData(drawn[1])

    def draw(self, u, values, eroded, loose, time: str) -> np.ndarray:
        """The picture (h, w, 3 uint8) of the body displaced by ``u`` ((n, 3), m) coloured
        by ``values``, without the cells where ``eroded`` (or None) is 1, with the nodes
        where ``loose`` (or None) is 1 as points, labelled ``time``."""
        self._xyz[:] = self.points0 + u
        self.grid.GetPoints().GetData().Modified()
        self.grid.GetPoints().Modified()
        self._values[:] = values
        (self.grid.GetCellData() if self.paint.per_cell else self.grid.GetPointData()).GetArray(
            "colour"
        ).Modified()
        if self._live is not None and eroded is not None:
            self._live[:] = 1.0 - eroded
            self.grid.GetCellData().GetArray("live").Modified()
        self.grid.Modified()
        points = self._xyz[loose > 0.5] if loose is not None else np.zeros((0, 3))
        if self.cut is not None and len(points):  # the loose nodes of the kept side
            points = points[(points - self.cut[0]) @ self.cut[1] <= 0.0]
        self._loose.ShallowCopy(polydata(points) if len(points) else vtkPolyData())
        self._time.SetInput(time)
        self._window.Render()
        self._grab.Modified()
        self._grab.Update()
        image = self._grab.GetOutput()
        width, height, _ = image.GetDimensions()
        pixels = vtk_to_numpy(image.GetPointData().GetScalars()).reshape(height, width, -1)
        return np.ascontiguousarray(pixels[::-1, :, :3])  # VTK's rows run from the bottom

    def close(self) -> None:
        self._window.Finalize()

    # --- the colour bar -----------------------------------------------------------------

    def _colour_bar(self) -> None:
        """The colour bar under the picture: the bar from VTK, its title above it and its
        labels (in one format, at round values) under it, placed here: VTK's own placement
        lets them overlap the bar and each other."""
        paint, (w, h) = self.paint, self.size
        bar = vtkScalarBarActor()
        bar.SetLookupTable(self._lut)
        bar.SetOrientationToHorizontal()
        bar.SetTitle("")
        bar.SetDrawTickLabels(False)
        bar.SetNumberOfLabels(0)
        bar.SetBarRatio(1.0)  # the bar fills its box
        bar.SetMaximumNumberOfColors(len(paint.names) or 256)
        coordinate = bar.GetPositionCoordinate()
        coordinate.SetCoordinateSystemToNormalizedViewport()
        coordinate.SetValue(BAR[0], BAR[1])
        bar.SetWidth(BAR[2])
        bar.SetHeight(BAR[3])
        self.renderer.AddViewProp(bar)
        (left, bottom), width = np.multiply(BAR[:2], self.size), BAR[2] * w
        (low, high), n = paint.clim, paint.n_labels
        if paint.names:  # categories: each name under the middle of its colour
            labels = [(name, (i + 0.5) / n) for i, name in enumerate(paint.names)]
        else:  # + 0.0: no "-0"
            labels = [(paint.fmt % (low + (high - low) * i / (n - 1) + 0.0), i / (n - 1))
                      for i in range(n)]  # fmt: skip
        for text, at in labels:
            self._centred_text(text, left + width * at, bottom - 20, 10)
        self._centred_text(paint.title, w / 2, bottom + BAR[3] * h + 6, 11)

    def _centred_text(self, text: str, x: float, y: float, size: int) -> None:
        """``text`` centred on ``x`` with its foot at ``y`` (pixels from the lower left)."""
        self._text(text, x, y, size).GetTextProperty().SetJustificationToCentered()

    def _text(self, text: str, x: float, y: float, size: int):
        """A black label at (``x``, ``y``) pixels from the lower left, of ``size`` points
        (doubled: pyvista's sizes, which the pictures had first)."""
        actor = vtkTextActor()
        actor.SetInput(text)
        actor.SetPosition(x, y)
        prop = actor.GetTextProperty()
        prop.SetFontSize(int(2 * size))
        prop.SetColor(0.0, 0.0, 0.0)
        prop.SetFontFamilyToArial()
        self.renderer.AddViewProp(actor)
        return actor

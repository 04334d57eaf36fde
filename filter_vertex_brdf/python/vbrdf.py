"""Vertex BRDF in PyMeshLab: loads the plugin built for MeshLab 2025.07, binds its filters as
MeshSet methods and runs them on MeshLab projects.

    import vbrdf
    result = vbrdf.fit("sample_projects/synth_basic/project.mlp")
    print(result.ply, result.report, result.figures["vertices_coloured"])

The plugin is the one ``cmake -DVBRDF_MESHLAB=2025.07`` builds (docs/pymeshlab.md); its path is
taken from the argument of ``load()``, else from the environment variable VBRDF_PYMESHLAB_PLUGIN,
else from the repository's build/pymeshlab folder. PyMeshLab returns numbers only (strings are
dropped from a filter's output), so the paths of the results are the ones this module passes to
the filter, and everything else is in the report file beside the result.
"""
from __future__ import annotations

import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Dict, Mapping, Optional, Union


def _qt_plugins_of_the_wheels_qt() -> None:
    """Qt's plugins (image formats: JPEG, TIFF; platforms: OpenGL under a display) of the wheel's Qt
    version, from PyQt5-Qt5 5.15.2 when installed beside pymeshlab: the wheel carries none. Set
    before pymeshlab starts Qt; an explicit QT_PLUGIN_PATH is kept."""
    import sysconfig
    plugins = Path(sysconfig.get_paths()["purelib"]) / "PyQt5" / "Qt5" / "plugins"
    if "QT_PLUGIN_PATH" not in os.environ and plugins.is_dir():
        os.environ["QT_PLUGIN_PATH"] = str(plugins)


_qt_plugins_of_the_wheels_qt()
import pymeshlab  # noqa: E402  (after QT_PLUGIN_PATH)

PathLike = Union[str, "os.PathLike[str]"]

PLUGIN_ENV = "VBRDF_PYMESHLAB_PLUGIN"
_REPO = Path(__file__).resolve().parents[2]  # filter_vertex_brdf/python/vbrdf.py
DEFAULT_PLUGIN = _REPO / "build" / "pymeshlab" / "filter_vertex_brdf" / "plugin" / "libfilter_vertex_brdf.so"

# The filters by their MeshLab names (menu entries, .mlx names); PyMeshLab's method names are
# derived from them (lower case, words joined by '_', punctuation dropped).
FILTERS = {
    "fit": "Vertex BRDF: fit per-vertex reflectance",
    "relight": "Vertex BRDF: relight and compare",
    "sphere": "Vertex BRDF: estimate light directions from a reflective sphere",
    "coverage": "Vertex BRDF: coverage and next light",
    "import_photos": "Vertex BRDF: import new photos of a viewpoint",
    "load_result": "Vertex BRDF: load result attributes",
    "show_colors": "Vertex BRDF: show vertex colours",
}

_loaded: Optional[Path] = None


def python_name(meshlab_name: str) -> str:
    """PyMeshLab's name for a MeshLab filter or parameter name (pymeshlab::computePythonName)."""
    name = meshlab_name.lower().replace(" ", "_").replace("/", "_").replace("-", "_")
    return "".join(c for c in name if c not in "().,'\":+")


def method_name(filter_key: str) -> str:
    """The MeshSet method of a filter of FILTERS, e.g. method_name('fit')."""
    return python_name(FILTERS[filter_key])


def plugin_path(plugin: Optional[PathLike] = None) -> Path:
    """The plugin file load() uses: `plugin`, else $VBRDF_PYMESHLAB_PLUGIN, else the build's."""
    if plugin is not None:
        return Path(plugin)
    return Path(os.environ.get(PLUGIN_ENV) or DEFAULT_PLUGIN)


def load(plugin: Optional[PathLike] = None) -> Path:
    """Loads the plugin into PyMeshLab (once) and binds its filters as MeshSet methods.

    Raises FileNotFoundError naming the path and how to build it when the file is missing, and
    pymeshlab.PyMeshLabException when PyMeshLab refuses it."""
    global _loaded
    path = plugin_path(plugin).resolve()
    if _loaded is not None:
        return _loaded
    if not path.is_file():
        raise FileNotFoundError(
            f"Vertex BRDF plugin for PyMeshLab not found at '{path}': build it with "
            "'bash .ci/build-pymeshlab.sh' (docs/pymeshlab.md) or set VBRDF_PYMESHLAB_PLUGIN to its path.")
    pymeshlab.load_plugin(str(path))
    for key in FILTERS:
        name = method_name(key)
        setattr(pymeshlab.MeshSet, name, pymeshlab.bind_function(name))
    _loaded = path
    return path


@dataclass
class Result:
    """What a filter run produced: its output files, the figures PyMeshLab returned, the report."""
    meshset: pymeshlab.MeshSet
    figures: Dict[str, float] = field(default_factory=dict)
    ply: Optional[Path] = None
    report: Optional[Path] = None

    @property
    def report_text(self) -> str:
        """The report file's text ('' when the filter writes none)."""
        return self.report.read_text(encoding="utf-8") if self.report and self.report.is_file() else ""


def _parameters(params: Mapping[str, object]) -> Dict[str, object]:
    """Parameters by MeshLab name ('lightFile') or PyMeshLab name ('lightfile') -> PyMeshLab's."""
    return {python_name(k): (str(v) if isinstance(v, os.PathLike) else v) for k, v in params.items()}


def script_parameters(mlx: PathLike, filter_key: Optional[str] = None) -> Dict[str, object]:
    """The parameter values a MeshLab filter script (.mlx, as meshlabserver 2020.09 runs it) gives
    the filter `filter_key` (default: its first filter), by MeshLab name, ready for apply() or fit():
    a 2020.09 script's settings run unchanged through PyMeshLab."""
    import xml.etree.ElementTree as ET
    filters = list(ET.parse(str(mlx)).getroot().iter("filter"))
    if filter_key is not None:
        filters = [f for f in filters if f.get("name") == FILTERS[filter_key]]
    if not filters:
        raise ValueError(f"'{mlx}' has no filter '{FILTERS.get(filter_key, filter_key)}'")
    values: Dict[str, object] = {}
    for p in filters[0].iter("Param"):
        kind, value = p.get("type"), p.get("value")
        if kind == "RichBool":
            values[p.get("name")] = value.lower() == "true"
        elif kind in ("RichInt", "RichEnum"):
            values[p.get("name")] = int(value)
        elif kind in ("RichFloat", "RichDynamicFloat", "RichAbsPerc"):
            values[p.get("name")] = float(value)
        elif kind in ("RichPoint3f", "RichPosition", "RichDirection"):
            import numpy
            values[p.get("name")] = numpy.array([float(p.get(c)) for c in "xyz"])
        else:
            values[p.get("name")] = value
    return values


def open_project(project: PathLike, meshset: Optional[pymeshlab.MeshSet] = None) -> pymeshlab.MeshSet:
    """A MeshSet holding the project (mesh and rasters), the plugin loaded."""
    load()
    project = Path(project)
    if not project.is_file():
        raise FileNotFoundError(f"Project '{project}' not found: give the path of a MeshLab project (.mlp).")
    ms = meshset if meshset is not None else pymeshlab.MeshSet()
    ms.load_project(str(project))
    return ms


def apply(filter_key: str, project: PathLike, meshset: Optional[pymeshlab.MeshSet] = None,
          **params: object) -> Result:
    """Runs a filter of FILTERS on the project with the given parameters (MeshLab or PyMeshLab
    names); the project's path is passed as 'Project file', which PyMeshLab does not tell filters."""
    project = Path(project).resolve()
    ms = open_project(project, meshset)
    kwargs = _parameters(params)
    kwargs["projectfile"] = str(project)
    figures = ms.apply_filter(method_name(filter_key), **kwargs) or {}
    return Result(meshset=ms, figures=dict(figures))


def default_output(project: PathLike) -> Path:
    """The fit's default result beside the project: <project>_brdf.ply."""
    project = Path(project)
    return project.with_name(project.stem + "_brdf.ply")


def report_of(ply: PathLike) -> Path:
    """The report the fit writes beside its result: <name>_report.txt."""
    ply = Path(ply)
    return ply.with_name(ply.stem + "_report.txt")


def fit(project: PathLike, lights: Optional[PathLike] = None, out: Optional[PathLike] = None,
        meshset: Optional[pymeshlab.MeshSet] = None, **params: object) -> Result:
    """Fits the per-vertex reflectance of the project's mesh from its photos.

    project: the .mlp (mesh with normals, registered rasters); lights: the light file (.lp, .json,
    .dome; default: the newest .lp beside the project or the photos that lists every raster); out:
    the result PLY (default <project>_brdf.ply beside the project; its report beside it). Other
    parameters by their names in docs/parameters.md (e.g. fitBackend=2, findMaterials=False).
    Raises pymeshlab.PyMeshLabException with the filter's message on bad input (nothing written)."""
    ply = Path(out).resolve() if out is not None else default_output(Path(project).resolve())
    params = dict(params)
    params["outputPly"] = str(ply)
    if lights is not None:
        params["lightFile"] = str(Path(lights).resolve())
    result = apply("fit", project, meshset, **params)
    result.ply, result.report = ply, report_of(ply)
    return result

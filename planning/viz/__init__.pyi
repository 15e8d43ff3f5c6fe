"""Type stub of the package: what it exports, and from which module (read by ``lazy_loader``)."""

from .artifacts import PLOT_FILES, notebook_viewer, plot_files, viewer_html
from .viewer import Viewer
from .viewer_server import ServerProcess, start_server

__all__ = [
    "PLOT_FILES",
    "ServerProcess",
    "Viewer",
    "notebook_viewer",
    "plot_files",
    "start_server",
    "viewer_html",
]

"""Reading and writing files atomically: VTK files (``.vtp`` polydata, ``.vtm`` multiblocks) and PNGs,
and telling whether an existing file was written by warpviz.

Every writer here goes through :func:`atomic_write` (or, for a ``.vtm`` and its folder of pieces,
the same staging idea applied to a folder): the data is first written into a hidden staging folder
next to the target and then moved into place with :func:`os.replace`, so a reader never sees a
half-written file and a failed write leaves an existing file untouched. Every file warpviz writes names
itself (a PNG's ``Software`` text, an EXR's ``Software`` header, a ``.vtp``'s ``warpviz_version`` field),
so :func:`written_by_warpviz` can tell the command line which existing files it may replace. PyVista, VTK,
Pillow and OpenEXR are imported on first use, so ``import warpviz`` stays fast.

Examples
--------
>>> import pathlib, tempfile
>>> from warpviz.io import atomic_write
>>> with tempfile.TemporaryDirectory() as folder:
...     print(atomic_write(pathlib.Path(folder) / "note.txt", lambda tmp: tmp.write_text("hello")).read_text())
...     print(sorted(p.name for p in pathlib.Path(folder).iterdir()))
hello
['note.txt']
"""

from __future__ import annotations

import contextlib
import errno
import os
import secrets
import shutil
import tempfile
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:  # pragma: no cover
    import pyvista as pv

__all__ = ["atomic_write", "check_writable", "name_length_problem", "read_rays", "software", "write_png", "write_vtm", "write_vtp", "written_by_warpviz"]

#: The PNG text key and EXR header attribute that name the program that wrote a file.
SOFTWARE_KEY = "Software"


def software() -> str:
    """``"warpviz VERSION"``: what every image warpviz writes says under :data:`SOFTWARE_KEY`."""
    from warpviz import __version__

    return f"warpviz {__version__}"


def write_png(path: str | os.PathLike, pixels, *, text: dict[str, str] | None = None) -> Path:
    """Write an 8-bit picture as a PNG, atomically, marked as written by warpviz.

    Parameters
    ----------
    path : str or os.PathLike
        Destination ``.png``; its folder must exist.
    pixels : numpy.ndarray
        (H, W, 3) or (H, W, 4) uint8.
    text : dict of str, optional, keyword-only
        More text chunks (e.g. the render's metadata).

    Returns
    -------
    pathlib.Path
        ``path``.
    """
    from PIL import Image as PILImage
    from PIL.PngImagePlugin import PngInfo

    info = PngInfo()
    info.add_text(SOFTWARE_KEY, software())
    for key, value in (text or {}).items():
        info.add_text(key, value)
    return atomic_write(_target(path, ".png"), lambda tmp: PILImage.fromarray(pixels).save(tmp, format="PNG", pnginfo=info))


def written_by_warpviz(path: str | os.PathLike) -> bool:
    """Whether the existing file ``path`` is one warpviz wrote (and may therefore replace).

    Parameters
    ----------
    path : str or os.PathLike
        A ``.png``, ``.exr`` or ``.vtp`` file.

    Returns
    -------
    bool
        True for a PNG whose ``Software`` text or an EXR whose ``Software`` header starts with
        ``warpviz``, or a ``.vtp`` with a ``warpviz_version`` field; False for anything else, including
        files that cannot be read.
    """
    path = Path(path)
    suffix = path.suffix.lower()
    try:
        if suffix == ".png":
            from PIL import Image as PILImage

            with PILImage.open(path) as im:
                return str(im.info.get(SOFTWARE_KEY, "")).startswith("warpviz")
        if suffix == ".exr":
            import OpenEXR

            with OpenEXR.File(str(path), header_only=True) as f:
                return str(f.header().get(SOFTWARE_KEY, "")).startswith("warpviz")
        if suffix == ".vtp":
            with open(path, "rb") as f:
                head = f.read(1 << 16)  # the XML header, before the appended binary data
            return b"<VTKFile" in head[:512] and b'Name="warpviz_version"' in head
    except Exception:  # noqa: BLE001 - unreadable or not what its name says: not ours
        return False
    return False


def _target(path: str | os.PathLike, suffix: str) -> Path:
    """``path`` as a Path, checked to end in ``suffix`` and to name a file in an existing folder."""
    path = Path(path)
    if path.suffix.lower() != suffix:
        raise ValueError(f"expected a {suffix} file, got {str(path)!r}")
    return _writable(path)


def _writable(path: Path) -> Path:
    if not path.parent.is_dir():
        raise FileNotFoundError(f"cannot write {str(path)!r}: folder {str(path.parent)!r} does not exist")
    if path.is_dir():
        raise IsADirectoryError(f"cannot write {str(path)!r}: it is a folder")
    return path


@contextlib.contextmanager
def _staging(path: Path) -> Iterator[Path]:
    """A fresh hidden folder beside ``path`` (same file system, so renames out of it are atomic),
    removed with whatever is left in it when the block ends, also on error."""
    # a short name of its own: a file name near the system's 255-byte limit still fits inside it
    stage = Path(tempfile.mkdtemp(prefix=f".{path.name[:32]}.", suffix=".tmp", dir=path.parent))
    try:
        yield stage
    finally:
        shutil.rmtree(stage, ignore_errors=True)


def _fsync(path: Path) -> None:
    fd = os.open(path, os.O_RDONLY)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)


def name_length_problem(path: str | os.PathLike) -> str | None:
    """``"file name too long (N bytes; the file system allows M)"`` where ``path``'s last part is longer than
    its folder's file system allows (255 bytes where that cannot be asked), else None. It looks only at the
    folder, so it may be asked before anything else about ``path`` (which such a name makes fail)."""
    path = Path(path)
    name = len(os.fsencode(path.name))
    try:
        most = os.pathconf(path.parent if path.parent.is_dir() else ".", "PC_NAME_MAX")
    except (OSError, ValueError):
        most = 255
    return f"file name too long ({name} bytes; the file system allows {most})" if name > most else None


def check_writable(path: str | os.PathLike) -> Path:
    """Check, before the work that produces it, that :func:`atomic_write` will be able to write ``path``:
    its staging folder and a file of ``path``'s name in it are created and removed again (``path``
    itself is not touched).

    Parameters
    ----------
    path : str or os.PathLike

    Returns
    -------
    pathlib.Path
        ``path``.

    Raises
    ------
    OSError
        ``strerror`` says why in words: the name is longer than the file system allows, permission
        denied, a read-only file system, ... (:class:`FileNotFoundError` / :class:`IsADirectoryError`
        for a missing folder or a folder given as the file).
    """
    path = Path(path)
    problem = name_length_problem(path)
    if problem:
        raise OSError(errno.ENAMETOOLONG, problem)
    path = _writable(path)
    try:
        with _staging(path) as stage:
            (stage / path.name).touch()
    except OSError as exc:
        reason = {errno.ENAMETOOLONG: "file name too long", errno.EACCES: "permission denied",
                  errno.EPERM: "permission denied", errno.EROFS: "the file system is read-only",
                  errno.ENOSPC: "no space left on the device", errno.EDQUOT: "disk quota exceeded",
                  errno.ENOENT: "its folder cannot hold new files"}.get(exc.errno, exc.strerror or str(exc))  # fmt: skip
        raise OSError(exc.errno, reason) from None
    return path


def atomic_write(path: str | os.PathLike, writer: Callable[[Path], object]) -> Path:
    """Write a file all at once or not at all.

    ``writer(tmp)`` writes the complete file at the temporary path ``tmp`` (same name as ``path``,
    inside a hidden staging folder in ``path``'s folder); the file is then flushed to disk and
    renamed onto ``path`` with :func:`os.replace`, which is atomic on POSIX and Windows. If
    ``writer`` raises, or creates no file, the staging folder is removed, the error propagates and
    an existing ``path`` is left as it was.

    Parameters
    ----------
    path : str or os.PathLike
        Destination file. Its folder must exist.
    writer : callable
        ``writer(tmp: pathlib.Path)``; its return value is ignored. ``tmp`` ends with the same
        suffix as ``path``, so writers that choose a format by suffix work unchanged.

    Returns
    -------
    pathlib.Path
        ``path``.

    Raises
    ------
    FileNotFoundError
        The folder of ``path`` does not exist.
    OSError
        ``writer`` returned without creating ``tmp``.

    Examples
    --------
    >>> import pathlib, tempfile
    >>> def broken(tmp):
    ...     tmp.write_text("half")
    ...     raise RuntimeError("disk on fire")
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     target = atomic_write(pathlib.Path(folder) / "data.txt", lambda tmp: tmp.write_text("old"))
    ...     try:
    ...         atomic_write(target, broken)
    ...     except RuntimeError as exc:
    ...         print(exc)
    ...     print(target.read_text(), len(list(target.parent.iterdir())))
    disk on fire
    old 1
    """
    path = _writable(Path(path))
    with _staging(path) as stage:
        tmp = stage / path.name
        writer(tmp)
        if not tmp.is_file():
            raise OSError(f"writing {str(path)!r} failed: the writer created no file")
        _fsync(tmp)
        os.replace(tmp, path)
    return path


def _run_vtk_writer(writer, data, filename: Path) -> None:
    writer.SetFileName(str(filename))
    writer.SetInputData(data)
    writer.SetDataModeToAppended()
    writer.EncodeAppendedDataOff()  # raw binary: exact float64 round trip, smallest file
    writer.SetCompressorTypeToZLib()
    writer.SetHeaderTypeToUInt64()
    if writer.Write() != 1:
        raise OSError(f"VTK could not write {filename.name!r} (see the VTK error above)")


def write_vtp(polydata: pv.PolyData, path: str | os.PathLike) -> Path:
    """Write polydata to a VTK XML ``.vtp`` file, atomically.

    Arrays are stored as zlib-compressed raw binary, so every value (float64 points included) reads
    back bit for bit.

    Parameters
    ----------
    polydata : pyvista.PolyData or vtkPolyData
        What to write, with its point, cell and field data.
    path : str or os.PathLike
        Destination ending in ``.vtp``; an existing file is replaced.

    Returns
    -------
    pathlib.Path
        ``path``.

    Raises
    ------
    ValueError
        ``path`` does not end in ``.vtp``.
    TypeError
        ``polydata`` is not polydata.

    Examples
    --------
    >>> import pathlib, tempfile, pyvista as pv
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     path = write_vtp(pv.Line(), pathlib.Path(folder) / "line.vtp")
    ...     print(pv.read(path).n_points)
    2
    >>> write_vtp(pv.Line(), "line.vtk")
    Traceback (most recent call last):
    ...
    ValueError: expected a .vtp file, got 'line.vtk'
    """
    from vtkmodules.vtkCommonDataModel import vtkPolyData
    from vtkmodules.vtkIOXML import vtkXMLPolyDataWriter

    path = _target(path, ".vtp")
    if not isinstance(polydata, vtkPolyData):
        raise TypeError(f"write_vtp needs pyvista.PolyData, got {type(polydata).__name__}")
    return atomic_write(path, lambda tmp: _run_vtk_writer(vtkXMLPolyDataWriter(), polydata, tmp))


def write_vtm(multiblock: pv.MultiBlock, path: str | os.PathLike) -> Path:
    """Write a multiblock to a VTK XML ``.vtm`` file and its folder of pieces, replacing both.

    A ``scene.vtm`` names its blocks and points to one file per block in the folder ``scene/`` next
    to it. Both are written into a hidden staging folder first; then an existing ``scene/`` is moved
    aside, the new folder renamed into place and the new ``scene.vtm`` renamed over the old one,
    after which the old pieces are deleted. A failure before the renames leaves the old files
    untouched; the switch itself is three renames (not one atomic step), so a reader racing it can
    at worst find the folder of pieces briefly missing.

    Parameters
    ----------
    multiblock : pyvista.MultiBlock or vtkMultiBlockDataSet
        Blocks (possibly nested, possibly ``None``), with their names.
    path : str or os.PathLike
        Destination ending in ``.vtm``.

    Returns
    -------
    pathlib.Path
        ``path``.

    Raises
    ------
    ValueError
        ``path`` does not end in ``.vtm``.
    TypeError
        ``multiblock`` is not a multiblock.
    FileExistsError
        The sidecar folder name is taken by a file.

    Examples
    --------
    >>> import pathlib, tempfile, pyvista as pv
    >>> with tempfile.TemporaryDirectory() as name:
    ...     folder = pathlib.Path(name)
    ...     _ = write_vtm(pv.MultiBlock({"a": pv.Line(), "b": pv.Sphere()}), folder / "s.vtm")
    ...     print(sorted(p.name for p in folder.iterdir()), pv.read(folder / "s.vtm").keys())
    ['s', 's.vtm'] ['a', 'b']
    """
    from vtkmodules.vtkCommonDataModel import vtkMultiBlockDataSet
    from vtkmodules.vtkIOXML import vtkXMLMultiBlockDataWriter

    path = _target(path, ".vtm")
    if not isinstance(multiblock, vtkMultiBlockDataSet):
        raise TypeError(f"write_vtm needs pyvista.MultiBlock, got {type(multiblock).__name__}")
    pieces = path.with_suffix("")
    if pieces.exists() and not pieces.is_dir():
        raise FileExistsError(f"cannot write the pieces of {str(path)!r}: {str(pieces)!r} is a file")

    with _staging(path) as stage:
        _run_vtk_writer(vtkXMLMultiBlockDataWriter(), multiblock, stage / path.name)
        new_pieces = stage / pieces.name
        for file in [stage / path.name, *(p for p in new_pieces.rglob("*") if p.is_file())]:
            _fsync(file)
        old_pieces = None
        if pieces.is_dir():
            old_pieces = stage / f"old-{secrets.token_hex(4)}"
            os.rename(pieces, old_pieces)
        moved = False
        try:
            if new_pieces.is_dir():
                os.rename(new_pieces, pieces)
                moved = True
            os.replace(stage / path.name, path)
        except BaseException:
            if moved:
                shutil.rmtree(pieces, ignore_errors=True)
            if old_pieces is not None:
                os.rename(old_pieces, pieces)
            raise
    return path


def read_rays(path: str | os.PathLike) -> pv.PolyData:
    """Read rays saved by :meth:`RayBundle.save` (``.vtp``) or the ``rays`` block of a scene ``.vtm``.

    Parameters
    ----------
    path : str or os.PathLike
        A ``.vtp`` file, or a ``.vtm`` written by :func:`warpviz.save_scene_vtm` with rays in it.

    Returns
    -------
    pyvista.PolyData
        One polyline cell per ray, with the point, cell and field data described in
        :meth:`RayBundle.to_pyvista` (``ray_id`` cell data always present).

    Raises
    ------
    ValueError
        Wrong suffix, a ``.vtm`` without a ``rays`` block, or a file that is not a warpviz ray file.
    FileNotFoundError
        ``path`` does not exist.

    Examples
    --------
    >>> import pathlib, tempfile, warpviz as wv
    >>> rays = wv.trace(wv.Minkowski(), [0, 0, 0], [[1, 0, 0], [0, 1, 0]], record=True)
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     back = read_rays(rays.save(pathlib.Path(folder) / "rays.vtp"))
    >>> back.n_cells, back.cell_data["ray_id"].tolist()
    (2, [0, 1])
    """
    import pyvista as pv

    path = Path(path)
    suffix = path.suffix.lower()
    if suffix not in (".vtp", ".vtm"):
        raise ValueError(f"expected a .vtp file (or a scene .vtm), got {str(path)!r}")
    if not path.is_file():
        raise FileNotFoundError(f"no such file: {str(path)!r}")
    data = pv.read(path)
    if suffix == ".vtm":
        if "rays" not in data.keys():
            blocks = ", ".join(map(str, data.keys())) or "none"
            raise ValueError(f"{str(path)!r} has no 'rays' block (blocks: {blocks})")
        data = data["rays"]
    if not isinstance(data, pv.PolyData) or "ray_id" not in data.cell_data:
        raise ValueError(f"{str(path)!r} is not a warpviz ray file: no ray_id cell data")
    return data

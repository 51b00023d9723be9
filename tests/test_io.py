"""Result files: atomic writes that never destroy a previous result, one-line errors, reading
back, figure formats. The crash and open-file cases run in real subprocesses."""

import os
import subprocess
import sys
import textwrap

import numpy as np
import pytest
import xarray as xr

import nonsmooth as ns
from nonsmooth import io

OLD = xr.Dataset({"X": ("t", np.arange(5.0))}, attrs={"run": "old"})
NEW = xr.Dataset({"X": ("t", np.arange(7.0))}, attrs={"run": "new"})


def _leftovers(folder):
    return sorted(p.name for p in folder.iterdir() if p.name.startswith("."))


def _run(code: str, **kw) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-c", textwrap.dedent(code)], capture_output=True,
                          text=True, timeout=120, **kw)


def test_overwrite_while_another_process_holds_the_file_open(tmp_path):
    path = tmp_path / "r.nc"
    io.save_dataset(OLD, path)
    reader = subprocess.Popen(
        [sys.executable, "-c", textwrap.dedent(f"""
            import sys, xarray as xr
            ds = xr.open_dataset({str(path)!r}, engine="h5netcdf")
            print("open", flush=True)
            sys.stdin.readline()
            print(ds.attrs["run"], int(ds.sizes["t"]), flush=True)
        """)], stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)
    try:
        assert reader.stdout.readline().strip() == "open"
        io.save_dataset(NEW, path)  # before the fix: "unable to lock file", r.nc left empty
        out, _ = reader.communicate("go\n", timeout=60)
    finally:
        reader.kill()
    assert out.split() == ["old", "5"]  # the reader kept its file
    back = io.load_dataset(path)
    assert back.attrs["run"] == "new" and back.sizes["t"] == 7
    assert _leftovers(tmp_path) == []


def test_failed_write_leaves_the_previous_file_untouched(tmp_path, monkeypatch):
    path = tmp_path / "r.nc"
    io.save_dataset(OLD, path)
    before = path.read_bytes()

    def broken(self, target, *args, **kwargs):
        with open(target, "wb") as f:
            f.write(b"partial")
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(xr.Dataset, "to_netcdf", broken)
    with pytest.raises(ns.OutputError) as exc:
        io.save_dataset(NEW, path)
    msg = str(exc.value)
    assert "\n" not in msg and msg.startswith("output: cannot write") and "r.nc" in msg
    assert "No space left on device" in msg and "previous file is untouched" in msg
    assert path.read_bytes() == before
    assert _leftovers(tmp_path) == []


def test_kill_during_write_leaves_the_previous_file_intact(tmp_path):
    path = tmp_path / "r.nc"
    io.save_dataset(OLD, path)
    before = path.read_bytes()
    r = _run(f"""
        import os, numpy as np, xarray as xr
        from nonsmooth import io

        def crash(self, target, *args, **kwargs):
            with open(target, "wb") as f:
                f.write(b"half a netCDF file")
                f.flush()
            os._exit(137)  # as if killed with SIGKILL in the middle of the write

        xr.Dataset.to_netcdf = crash
        io.save_dataset(xr.Dataset({{"X": ("t", np.zeros(3))}}), {str(path)!r})
    """)
    assert r.returncode == 137, r.stderr
    assert path.read_bytes() == before
    assert io.load_dataset(path).attrs["run"] == "old"


def test_interrupted_write_removes_its_temporary_file(tmp_path, monkeypatch):
    path = tmp_path / "r.nc"
    io.save_dataset(OLD, path)

    def interrupted(self, target, *args, **kwargs):
        open(target, "wb").close()
        raise KeyboardInterrupt

    monkeypatch.setattr(xr.Dataset, "to_netcdf", interrupted)
    with pytest.raises(KeyboardInterrupt):
        io.save_dataset(NEW, path)
    assert io.load_dataset(path).attrs["run"] == "old"
    assert _leftovers(tmp_path) == []


def test_written_files_are_recorded_and_keep_the_permissions(tmp_path):
    path = tmp_path / "r.nc"
    io.save_dataset(OLD, path)
    os.chmod(path, 0o640)
    io.save_dataset(NEW, path)
    assert oct(path.stat().st_mode & 0o777) == oct(0o640)
    text = io.write_file(tmp_path / "report.md", "# report\n")
    assert text.read_text() == "# report\n"
    assert io.written_files()[-3:] == [path, path, tmp_path / "report.md"]


def test_load_dataset_of_a_file_that_is_not_netcdf(tmp_path):
    bad = tmp_path / "notes.txt"
    bad.write_text("not a netCDF file\n")
    with pytest.raises(ns.OutputError) as exc:  # before: a raw OSError from h5py
        io.load_dataset(bad)
    assert "\n" not in str(exc.value) and "notes.txt" in str(exc.value)
    assert io.load_dataset.__doc__


def test_conventions_attribute_on_every_file_written(tmp_path):
    io.save_dataset(OLD, tmp_path / "r.nc")
    assert io.load_dataset(tmp_path / "r.nc").attrs["Conventions"] == io.CONVENTIONS


def test_figure_path_format_and_suffix(tmp_path):
    assert io.figure_path(tmp_path / "noext") == tmp_path / "noext.png"
    assert io.figure_path(tmp_path / "a.PDF") == tmp_path / "a.PDF"
    with pytest.raises(ns.OutputError) as exc:
        io.figure_path(tmp_path / "a.xyz", "orbits-plot")
    assert str(exc.value).startswith("orbits-plot: unknown figure format 'xyz'")


def test_save_figure_returns_the_path_written(tmp_path):
    from nonsmooth.plot.common import new_figure
    fig, ax = new_figure()
    ax.plot([0, 1])
    p = io.save_figure(fig, tmp_path / "noext")
    assert p == tmp_path / "noext.png" and p.read_bytes()[:4] == b"\x89PNG"
    assert not (tmp_path / "noext").exists() and _leftovers(tmp_path) == []


def test_from_attrs_refuses_a_swept_parameter_left_at_its_base_value():
    p = ns.preset("table3")
    ds = xr.Dataset(coords={"omega": [0.8, 0.9, 1.0]}, attrs=p.attrs())
    # before the fix: the base omega of the attrs came back silently
    with pytest.raises(ns.ParameterError) as exc:
        ns.model("support").params_from_attrs(ds)
    assert str(exc.value).startswith("omega: swept in this dataset")
    assert ns.model("support").params_from_attrs(ds, omega=0.9) == p.replace(omega=0.9)
    assert ns.model("support").params_from_attrs(p.attrs()) == p
    attrs = io.provenance_attrs(p, swept=("omega",))
    assert "param_omega" not in attrs and attrs["param_F0"] == p.F0
    with pytest.raises(ns.ParameterError, match="^omega: no param_omega attribute"):
        ns.model("support").params_from_attrs(attrs)
    with pytest.raises(ns.ParameterError, match="^nope: not a parameter of model 'support'"):
        ns.model("support").params_from_attrs(ds, nope=1.0)


def test_an_output_below_a_file_names_the_file_as_not_a_folder(tmp_path):
    """`-o afile/x.nc` with `afile` a file said "directory 'afile' does not exist" (a
    newcomer's finding); a missing folder still says it does not exist."""
    (tmp_path / "afile").write_text("")
    with pytest.raises(ns.errors.OutputError, match="afile' is a file, not a directory$"):
        io.check_writable(tmp_path / "afile" / "x.nc")
    with pytest.raises(ns.errors.OutputError, match="does not exist$"):
        io.check_writable(tmp_path / "nope" / "x.nc")


def test_an_output_the_filesystem_refuses_is_named_before_any_work(tmp_path, monkeypatch, capsys):
    """As root, os.access says yes to /sys, whose filesystem then refuses the file: the error
    named the sweep's chunk store (``store: cannot write '/sys/b.nc.chunks'``) instead of the
    output. A file is now made and removed in the folder before any work."""
    import errno
    real_open = os.open

    def refusing(path, *a, **k):
        if str(path).endswith(".probe"):
            raise OSError(errno.EPERM, "Operation not permitted")
        return real_open(path, *a, **k)

    monkeypatch.setattr(os, "open", refusing)
    with pytest.raises(ns.errors.OutputError,
                       match=r"^output: cannot write '.*b\.nc': Operation not permitted$"):
        io.check_writable(tmp_path / "b.nc")
    from cli_helpers import one_line, run_cli
    code, _, err = run_cli(["bifurcation", "--from", "0.9", "--to", "0.91", "--steps", "2", "-o",
                            str(tmp_path / "b.nc")], capsys)
    assert code == 2
    one_line(err, "output: cannot write")
    monkeypatch.setattr(os, "open", real_open)
    assert io.check_writable(tmp_path / "b.nc") == tmp_path / "b.nc"
    assert list(tmp_path.iterdir()) == []  # the probe is removed

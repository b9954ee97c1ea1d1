"""isoflex: flexible multibody dynamics and isogeometric Kirchhoff–Love shells (docs/python.md).

    import isoflex
    model = isoflex.Model("examples/slider_crank_flexible/model.yaml")
    model.set("solver.t_end", 1.0)
    sim = isoflex.Simulation(model)
    results = sim.run()            # history.csv's columns as numpy arrays, and the probes
    results["total_energy"], sim.state.q, sim.probes["connection"]["position"]
"""

import json
import math
import os

from ._isoflex import (  # noqa: F401  (the public names of the package)
    CadError,
    CompileError,
    Error,
    ModelError,
    NewtonFailure,
    OutputError,
    State,
)
from . import _isoflex

__all__ = ["Model", "Simulation", "check", "cad_info", "Error", "ModelError", "CompileError",
           "NewtonFailure", "OutputError", "CadError", "State"]


def _scalar(value, where):
    """A YAML scalar for a Python value (JSON's strings are YAML's double-quoted ones)."""
    if value is None:
        return "null"
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        if math.isnan(value):
            return ".nan"
        if math.isinf(value):
            return ".inf" if value > 0 else "-.inf"
        return repr(value)
    if isinstance(value, str):
        return json.dumps(value, ensure_ascii=False)
    if hasattr(value, "tolist"):  # numpy scalars and arrays
        return None
    raise TypeError(f"{where or 'the model'}: {type(value).__name__} is no model value "
                    "(use dict, list, str, int, float, bool or None)")


def _to_yaml(value, path="", indent=0):
    """YAML text of a model given as a dict, one entry per line, and the key path of each line
    (the location of a message about that line)."""
    lines, paths = [], []
    pad = " " * indent

    def entry(prefix, child, child_path):
        if hasattr(child, "tolist"):
            child = child.tolist()
        if isinstance(child, dict) and child:
            lines.append(f"{pad}{prefix}")
            paths.append(child_path)
            sub_lines, sub_paths = _to_yaml(child, child_path, indent + 2)
            lines.extend(sub_lines)
            paths.extend(sub_paths)
        elif isinstance(child, (list, tuple)) and child:
            lines.append(f"{pad}{prefix}")
            paths.append(child_path)
            sub_lines, sub_paths = _to_yaml(list(child), child_path, indent + 2)
            lines.extend(sub_lines)
            paths.extend(sub_paths)
        else:
            text = ("{}" if isinstance(child, dict) else "[]" if isinstance(child, (list, tuple))
                    else _scalar(child, child_path))
            lines.append(f"{pad}{prefix} {text}")
            paths.append(child_path)

    if isinstance(value, dict):
        for key, child in value.items():
            if not isinstance(key, str):
                raise TypeError(f"{path or 'the model'}: key {key!r} is not a string")
            entry(f"{json.dumps(key, ensure_ascii=False)}:", child,
                  f"{path}.{key}" if path else key)
    else:
        for k, child in enumerate(value):
            item_path = f"{path}[{k}]"
            if isinstance(child, dict) and child:
                # "- key: value" on the first line, the other keys below it
                sub_lines, sub_paths = _to_yaml(child, item_path, indent + 2)
                sub_lines[0] = pad + "- " + sub_lines[0][indent + 2:]
                lines.extend(sub_lines)
                paths.extend(sub_paths)
            else:
                entry("-", child, item_path)
    return lines, paths


def _value_text(value):
    """A --set VALUE (YAML) for a Python value."""
    if hasattr(value, "tolist"):
        value = value.tolist()
    return json.dumps(value) if isinstance(value, (dict, list, tuple, str)) else _scalar(value, "")


class Model:
    """A model read from a YAML file or a dict, checked as `isoflex run` checks it.

    Model(path) or Model(dict): a bad entry raises isoflex.ModelError naming the file and line
    (a file) or the key path (a dict). Relative file names inside a dict model (CAD files) are
    relative to the working directory.
    """

    def __init__(self, source):
        self._overrides = []
        if isinstance(source, (str, os.PathLike)):
            self._path, self._text, self._paths = os.fspath(source), None, None
        elif isinstance(source, dict):
            lines, self._paths = _to_yaml(source)
            self._path, self._text = None, "\n".join(lines) + "\n"
        else:
            raise TypeError("Model(source): a model file's path or a dict")
        self._data = self._read()

    def _read(self):
        try:
            return _isoflex.read_model(path=self._path, text=self._text, name="<dict>",
                                       overrides=self._overrides)
        except ModelError as e:
            if self._paths is None:
                raise
            # The generated YAML's line means nothing to the caller: the key path says where.
            key = e.key or (self._paths[e.line - 1] if 0 < e.line <= len(self._paths) else "")
            error = ModelError(f"<dict>: {key}: {e.message}" if key else f"<dict>: {e.message}")
            error.file, error.line, error.key, error.message = "<dict>", 0, key, e.message
            raise error from None

    def set(self, key, value):
        """Sets a model value as `--set KEY=VALUE` does: set("solver.dt", 1e-3),
        set("bodies[crank].mass", 2). Checked at once; a bad value raises ModelError and leaves
        the model as it was."""
        before = self._overrides
        self._overrides = [(k, v) for k, v in before if k != key] + [(key, _value_text(value))]
        try:
            self._data = self._read()
        except Exception:
            self._overrides = before
            raise
        return self

    @property
    def data(self):
        """The model as read (isoflex._isoflex.ModelData: dt, t_end, analysis, names)."""
        return self._data

    @property
    def file(self):
        return self._path

    def __repr__(self):
        source = self._path or "<dict>"
        sets = "".join(f", {k}={v}" for k, v in self._overrides)
        return f"isoflex.Model({source}{sets})"


def _model(model):
    return model if isinstance(model, Model) else Model(model)


class Simulation(_isoflex.Simulation):
    """A model compiled and set to t = 0, run step by step (step, run) or by load steps (solve).

    state: the current State (read-only numpy views q, v, lambda_, and t, step);
    energies, momenta, constraint_violation, probes, beam_resultants(), kl_displacement(): of
    the current state; results(): the history of every state so far, as history.csv.
    run() and solve() release the GIL; Ctrl-C stops them between two steps (KeyboardInterrupt),
    the simulation keeps the last step's state and results.
    """

    def __init__(self, model, threads=0):
        self.model = _model(model)
        super().__init__(self.model.data, threads)


def check(model):
    """What `isoflex check` reports, as a dict: n, m, dof, unknowns, redundant, tree_coordinates,
    memory_bytes, warnings, ... and the report's text under "report"."""
    return _isoflex.check(_model(model).data)


def cad_info(path):
    """The NURBS patches of an IGES or STEP file and their findings (`isoflex cad-info`)."""
    return _isoflex.cad_info(os.fspath(path))

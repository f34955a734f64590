"""Plain settings -> the native core's objects: ``SolverSettings`` to ``_native.SmokeParams``,
``SourceParams`` to ``_native.SourceSettings`` (same names on both sides; no ``bpy``)."""

import dataclasses


def to_native_params(solver, native):
    """SolverSettings -> validated ``native.SmokeParams``; ValueError (naming the setting) if bad."""
    p = native.SmokeParams()
    for f in dataclasses.fields(solver):
        value = getattr(solver, f.name)
        if f.name == "boundaries":
            value = [getattr(native.Boundary, b) for b in value]
        elif f.name == "advection":
            value = getattr(native.Advection, value)
        elif f.name == "interpolation":
            value = getattr(native.Interpolation, value)
        elif f.name == "trace":
            value = getattr(native.Trace, value)
        elif isinstance(value, list):
            value = tuple(value)
        setattr(p, f.name, value)
    p.validate()
    return p


def to_native_source(source, native):
    """SourceParams -> ``native.SourceSettings``, field by field (emit_particles is the tracer's,
    not the solver's)."""
    s = native.SourceSettings()
    for f in dataclasses.fields(source):
        if f.name != "emit_particles":
            value = getattr(source, f.name)
            setattr(s, f.name, tuple(value) if isinstance(value, (list, tuple)) else value)
    return s

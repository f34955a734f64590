"""The warning for fuel that never burns (no ``bpy``): Sources injecting Fuel into a domain whose
Combustion is off make no fire, and the first render is black. The Source panel draws it under
Fuel and Bake reports it (the bake still runs)."""


def _amount(value):
    """A setting's value as the panel shows it, short: 1.0, 0.25, 12.5."""
    text = f"{value:.3g}"
    return text if any(c in text for c in ".e") else text + ".0"


def fuel_without_combustion(sources, domains):
    """The warning when Sources inject fuel into domains with Combustion off (their fuel never
    burns: no fire, a first render is black), as lines, empty when there is nothing to say. The
    Source panel draws the lines, Bake reports them joined by spaces: the text is written here
    only. `sources`: (name, Fuel) of the Sources, a keyed Fuel's largest value; `domains`:
    (name, Combustion) of the domains they feed."""
    fueled = [(name, fuel) for name, fuel in sources if fuel > 0.0]
    off = [name for name, combustion in domains if not combustion]
    if not fueled or not off:
        return ()
    if len(fueled) == 1:
        what = f"Fuel {_amount(fueled[0][1])} of '{fueled[0][0]}'"
    else:
        what = "Fuel of " + ", ".join(f"'{n}' ({_amount(f)})" for n, f in fueled)
    where = ("the domain " if len(off) == 1 else "the domains ") + ", ".join(f"'{n}'" for n in off)
    return (f"{what} burns only with Combustion on:", f"select {where} and enable",
            "Physics › Plume › Combustion")


def unburnt_fuel(snap):
    """fuel_without_combustion() of a bake's snapshot: its Sources' largest Fuel over the frame
    range and its domain's Combustion (a domain tracing a Mantaflow cache has no fire of its
    own: nothing to say)."""
    if snap.mantaflow is not None:
        return ()
    sources = [(e.name, max(p.fuel for p in [e.source, *e.source_frames]))
               for e in snap.emitters if e.role == "SOURCE" and e.source is not None]
    return fuel_without_combustion(sources, [(snap.domain_name, snap.solver.combustion)])

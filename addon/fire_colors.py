"""The fire's colour by temperature, shared by the solver's combustion volume, the flow-graph
fire and the fire point preview (no ``bpy``).

Blackbody colours do not survive today's view transforms: AgX (Blender 4.x/5.x's default) turns
the 1200-2300 K reds a blackbody gives a flame's body into salmon pink (mean hue 16-17 degrees,
measured), and Filmic (3.4's) pushes bright orange to yellow. The ramp below is measured through
both instead (a flat emission of each linear colour at exposures 0.5-16, saved through each
Blender's default view transform): linear green/red g/r gives the display hue
  g/r   0.15  0.25  0.40  0.60      (intensity 1-4)
  AgX    12    19    27    37  deg
  Filmic 18-33 27-42 38-49 47-55 deg
so the body (0.35-0.55) reads orange-yellow (20-50 degrees) in both, the cool edge dark red, the
hottest gas yellow-white. Positions are the temperature over the domain's Max Temperature."""

#: (T / T_max, linear RGB) stops, ascending: ambient ... the reaction zone.
FIRE_RAMP = (
    (0.0, (0.30, 0.035, 0.005)),
    (0.25, (1.0, 0.20, 0.025)),
    (0.5, (1.0, 0.40, 0.07)),
    (0.8, (1.0, 0.55, 0.11)),
    (1.0, (1.0, 0.72, 0.18)),
)

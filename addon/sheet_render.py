"""A fast Cycles set-up for streak sheets ([Smoke Surfaces] §3.4; the paper: 4–5 s a frame).

The sheet material is emission mixed with transparency by p = d·e^(−|n·v|) (build/surfaces.py):
the sheets shade themselves and no light reaches them, so a camera ray only passes through layer
after layer, adding p × colour at each. Light bounces add nothing to that picture and cost most of
the render; transparency is handled by Cycles' transparent bounces, which must cover every layer a
ray crosses (with too few, the deepest layers are cut off and show as dark patches). Emission and
transparency are sampled without noise, so a few samples only antialias the edges.

Other objects in the scene lose their indirect light under this set-up: it is for sheet renders
(or a sheet layer composited over the rest)."""

#: Samples per pixel: antialiasing only (the sheets' shading is noise-free). Thin stems seen
#: edge-on, many layers to a pixel, still alias at 8 (the incense at 240 x 320: 19 levels off the
#: 64-sample picture at the 99.9th percentile; 10 at 16, 5 at 32).
FAST_SAMPLES = 16
#: Layers a ray may cross; the Figure 1 incense stacks up to about 20 where sheets fold.
TRANSPARENT_BOUNCES = 64
_NO_BOUNCES = ("max_bounces", "diffuse_bounces", "glossy_bounces", "transmission_bounces",
               "volume_bounces")


def apply_fast_cycles(scene, samples=FAST_SAMPLES, transparent_bounces=TRANSPARENT_BOUNCES):
    """Sets `scene` to Cycles with `samples` samples, no denoiser, no light bounces and
    `transparent_bounces` transparent ones. Leaves the device, resolution and output alone."""
    scene.render.engine = 'CYCLES'
    c = scene.cycles
    c.samples = samples
    c.use_adaptive_sampling = False
    c.use_denoising = False
    for name in _NO_BOUNCES:
        setattr(c, name, 0)
    c.transparent_max_bounces = transparent_bounces
    # No Russian roulette through the layers: Cycles ends some paths early once their throughput
    # is low (deep in a fold), which speckles a sheet render at a few samples; with every
    # transparent bounce kept, only the edges need the samples.
    c.min_transparent_bounces = transparent_bounces
    c.caustics_reflective = c.caustics_refractive = False


def describe(scene):
    """The report line of the set-up."""
    c = scene.cycles
    return (f"Cycles set for sheets: {c.samples} samples, no light bounces, "
            f"{c.transparent_max_bounces} transparent bounces (other objects lose indirect light)")

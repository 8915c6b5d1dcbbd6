#!/usr/bin/env python3
"""Writes the hard-case scenes of this folder (DESIGN section 10, issue 13); run it from here.
Each scene is small (tests render it in seconds); tests/trace/hard_cases_test.cpp holds the exact
references (closed forms, or double-precision quadrature) they are checked against."""
import json, math

WIDE_REFERENCE = 0.041667085565939968  # the quadrature's image mean (GgxPlane.DeclaredReferenceOfTheNearDeltaSceneIsTheQuadrature checks it)

def write(name, scene):
    with open(name, 'w') as f:
        json.dump(scene, f, indent=1)
        f.write('\n')

def ggx_scene(alpha, wide=False):
    # A GGX plane (R0 = 0.5) under a point light I = 1 at height 1, seen straight down by a pinhole at
    # height 2. The narrow scenes scale the field of view with alpha (film half-width 10 alpha) so
    # the highlight fills the image at every alpha; the wide one (60 degrees) keeps a 1e-3 highlight
    # far below a pixel, the near-delta case.
    fov = 60.0 if wide else 2 * math.degrees(math.atan(10 * alpha))
    return {
        "description": ("GGX plane, alpha %g, under a point light, " % alpha) +
                       ("a 60 degree view: the highlight is far below a pixel (near-delta)" if wide else
                        "film half-width 10 alpha: the highlight fills the image") +
                       "; reference: double-precision quadrature in tests/trace/hard_cases_test.cpp",
        "camera": {"type": "pinhole", "position": [0, 2, 0], "look_at": [0, 0, 0], "up": [0, 0, -1],
                   "fov": fov, "width": 32 if wide else 16, "height": 32 if wide else 16},
        "materials": {"ggx": {"type": "glossy", "reflectance": [0.5, 0.5, 0.5], "roughness": alpha}},
        "shapes": [{"type": "quad", "corner": [-3, 0, 3], "edge1": [6, 0, 0], "edge2": [0, 0, -6], "material": "ggx"}],
        "lights": [{"type": "point", "position": [0, 1, 0], "intensity": [1, 1, 1]}]}

for a in (0.1, 0.01, 0.001, 0.0001):
    write('ggx-point-%g.json' % a, ggx_scene(a))
# The near-delta scene `pathex converge` flags; its closed form is the quadrature (the test checks
# the declared value against it).
wide = ggx_scene(0.001, wide=True)
wide["reference"] = {"source": "double-precision quadrature over the film of the GGX reflection of the point light (tests/trace/hard_cases_test.cpp, GgxPlane.DeclaredReferenceOfTheNearDeltaSceneIsTheQuadrature)",
                     "classes": [{"name": "highlight", "class": "LSDDDSE", "luminance": WIDE_REFERENCE}]}
write('ggx-point-wide-0.001.json', wide)

# Albedo 1 in a closed box whose six walls emit Le = 1 and leave gaps of 1e-6 at every edge and
# corner (the box is 2 wide): with at most B bounces, paths of n bounces carry Le at every pixel.
g = 1e-6
walls = []
for axis in range(3):
    for side in (-1, 1):
        u, v = [(axis + 1) % 3, (axis + 2) % 3]
        c = [0.0, 0.0, 0.0]; c[axis] = side; c[u] = -1 + g; c[v] = -1 + g
        e1 = [0.0, 0.0, 0.0]; e1[u] = 2 - 2 * g
        e2 = [0.0, 0.0, 0.0]; e2[v] = 2 - 2 * g
        walls.append({"type": "quad", "corner": c, "edge1": e1, "edge2": e2, "material": "white",
                      "emission": [1, 1, 1], "two_sided": True})
write('white-box-gaps.json', {
    "description": "Albedo 1 in a closed box of emitting walls (Le = 1) with gaps of 1e-6 at every edge and corner: paths of n bounces carry Le at every pixel (furnace); the gaps leak about 1e-6 of it",
    "camera": {"type": "pinhole", "position": [0.1, -0.2, 0.3], "look_at": [0.9, 0.5, -1], "up": [0, 1, 0], "fov": 70, "width": 8, "height": 8},
    "materials": {"white": {"type": "diffuse", "albedo": [1, 1, 1]}},
    "shapes": walls})

# Ten glass interfaces in a row (five slabs, normals alternating so each slab is entered and left)
# between a pinhole and an area light, at normal incidence: the light through all of them is
# Le (1 - 0.04)^10.
slabs = []
for i in range(10):
    z = -1.0 - 0.1 * i
    n_towards_camera = i % 2 == 0
    e1 = [2, 0, 0]; e2 = [0, 2, 0]
    if not n_towards_camera: e1, e2 = e2, e1
    slabs.append({"type": "quad", "corner": [-1, -1, z], "edge1": e1, "edge2": e2, "material": "glass"})
write('ten-glass-interfaces.json', {
    "description": "Ten glass interfaces (ior 1.5, five slabs) between a pinhole and an area light (Le = 1), normal incidence: LDDS{10}DSE carries (1 - 0.04)^10",
    "camera": {"type": "pinhole", "position": [0, 0, 0], "look_at": [0, 0, -1], "up": [0, 1, 0], "fov": 1, "width": 8, "height": 8},
    "materials": {"glass": {"type": "dielectric", "ior": 1.5}, "black": {"type": "diffuse", "albedo": [0, 0, 0]}},
    "shapes": slabs + [{"type": "quad", "corner": [-2, -2, -3], "edge1": [4, 0, 0], "edge2": [0, 4, 0], "material": "black", "emission": [1, 1, 1]}]})

# Total internal reflection: a pinhole below the interface y = 0 (normal +y, glass below) looks up
# at 60 degrees from the normal, beyond the critical angle asin(1 / 1.5) = 41.8 degrees. The
# reflectance is exactly 1 there, so the pinhole sees the emitter below (Le = 0.5) and nothing of
# the emitter above (Le = 1): every pixel's LDDSDSE is exactly 0.5.
write('total-internal-reflection.json', {
    "description": "Total internal reflection: a pinhole inside glass (below the ior-1.5 interface y = 0) looks up at 60 degrees from the normal, beyond the critical angle of 41.8 degrees; it sees the emitter below (Le = 0.5) with reflectance 1 and nothing of the emitter above (Le = 1): LDDSDSE is exactly 0.5",
    "camera": {"type": "pinhole", "position": [0, -1, 0], "look_at": [math.sqrt(3) / 2, -0.5, 0], "up": [0, 0, 1], "fov": 1, "width": 8, "height": 8},
    "materials": {"glass": {"type": "dielectric", "ior": 1.5}, "black": {"type": "diffuse", "albedo": [0, 0, 0]}},
    "shapes": [{"type": "quad", "description": "the interface", "corner": [-20, 0, 20], "edge1": [40, 0, 0], "edge2": [0, 0, -40], "material": "glass"},
               {"type": "quad", "description": "the emitter below, facing up", "corner": [-20, -3, 20], "edge1": [40, 0, 0], "edge2": [0, 0, -40], "material": "black", "emission": [0.5, 0.5, 0.5]},
               {"type": "quad", "description": "the emitter above, facing down", "corner": [-20, 2, -20], "edge1": [40, 0, 0], "edge2": [0, 0, 40], "material": "black", "emission": [1, 1, 1]}]})

# Grazing at the light, the surface and the sensor (cos theta about 1e-6).
write('grazing-light.json', {
    "description": "A point light (I = 1) 1e-6 above a diffuse plane (albedo 0.5), seen from above around x = 1: light leaves the light and meets the surface at cos theta about 1e-6; L = rho I h / (pi d^3)",
    "camera": {"type": "pinhole", "position": [1, 1, 0], "look_at": [1, 0, 0], "up": [0, 0, -1], "fov": 20, "width": 8, "height": 8},
    "materials": {"plane": {"type": "diffuse", "albedo": [0.5, 0.5, 0.5]}},
    "shapes": [{"type": "quad", "corner": [-5, 0, 5], "edge1": [10, 0, 0], "edge2": [0, 0, -10], "material": "plane"}],
    "lights": [{"type": "point", "position": [0, 1e-6, 0], "intensity": [1, 1, 1]}]})
cos_g = 1e-6
write('grazing-surface.json', {
    "description": "Sunlight (irradiance E = 1 perpendicular to it) at cos theta = 1e-6 to a diffuse plane (albedo 0.5), seen from above: L = rho E cos theta / pi",
    "camera": {"type": "pinhole", "position": [0, 1, 0], "look_at": [0, 0, 0], "up": [0, 0, -1], "fov": 20, "width": 8, "height": 8},
    "materials": {"plane": {"type": "diffuse", "albedo": [0.5, 0.5, 0.5]}},
    "shapes": [{"type": "quad", "corner": [-5, 0, 5], "edge1": [10, 0, 0], "edge2": [0, 0, -10], "material": "plane"}],
    # The aperture sits where the grazing beam through it lands on the visible plane: 0.5 / 1e-6
    # upstream.
    "lights": [{"type": "distant", "direction": [math.sqrt(1 - cos_g ** 2), -cos_g, 0], "irradiance": [1, 1, 1],
                "aperture": {"corner": [-500001, 0.5, 1], "edge1": [2, 0, 0], "edge2": [0, 0, -2]}}]})
write('grazing-sensor.json', {
    "description": "A pinhole 1e-6 above a diffuse plane (albedo 0.5) lit straight down by sunlight (E = 1), looking along it: the lower half of the image sees the plane at cos theta down to 1e-6, L = rho E / pi; the upper half sees nothing",
    "camera": {"type": "pinhole", "position": [0, 1e-6, 0], "look_at": [0, 1e-6, -1], "up": [0, 1, 0], "fov": 30, "width": 8, "height": 8},
    "materials": {"plane": {"type": "diffuse", "albedo": [0.5, 0.5, 0.5]}},
    "shapes": [{"type": "quad", "corner": [-50, 0, 1], "edge1": [100, 0, 0], "edge2": [0, 0, -100], "material": "plane"}],
    "lights": [{"type": "distant", "direction": [0, -1, 0], "irradiance": [1, 1, 1],
                "aperture": {"corner": [-50, 1, 1], "edge1": [100, 0, 0], "edge2": [0, 0, -100]}}]})

# The Cornell box scaled by 1e-4 and 1e4, and moved 1e5 from the origin: the same image.
cornell = json.load(open('../cornell.json'))
def moved(scale, offset, name):
    s = json.loads(json.dumps(cornell))
    s["description"] = "cornell.json scaled by %g and moved by %g along each axis: the same image" % (scale, offset)
    def p(v): return [scale * x + offset for x in v]
    s["camera"]["position"] = p(s["camera"]["position"]); s["camera"]["look_at"] = p(s["camera"]["look_at"])
    s["camera"]["width"] = s["camera"]["height"] = 16
    for sh in s["shapes"]:
        for k in ("corner", "center"):
            if k in sh: sh[k] = p(sh[k])
        for k in ("edge1", "edge2"):
            if k in sh: sh[k] = [scale * x for x in sh[k]]
        if "radius" in sh: sh["radius"] = scale * sh["radius"]
        assert "file" not in sh and "transform" not in sh
    write(name, s)
moved(1.0, 0.0, 'cornell-16.json')
moved(1e-4, 0.0, 'cornell-1e-4.json')
moved(1e4, 0.0, 'cornell-1e+4.json')
moved(1.0, 1e5, 'cornell-moved-1e+5.json')

# Degenerate input beside the closed sphere of DESIGN section 9: a mesh of degenerate triangles
# (a repeated vertex, three collinear points), a zero-area emissive triangle and a zero-power
# point light change nothing.
with open('degenerate.obj', 'w') as f:
    f.write("# degenerate triangles: a repeated vertex, collinear points\n"
            "v 0.1 0.1 0.1\nv 0.2 0.1 0.1\nv 0.3 0.1 0.1\nv 0.1 0.1 0.1\n"
            "f 1 2 4\nf 1 2 3\n")
sphere = json.load(open('../closed-sphere-point.json'))
sphere["description"] = "closed-sphere-point.json with degenerate triangles, a zero-area emissive triangle and a zero-power point light inside: the same closed form"
sphere["camera"]["width"] = sphere["camera"]["height"] = 12
sphere["shapes"] += [{"type": "mesh", "file": "degenerate.obj", "material": "wall"},
                     {"type": "mesh", "file": "degenerate.obj", "material": "wall", "emission": [5, 5, 5]}]
sphere["lights"].append({"type": "point", "position": [0.2, 0.1, 0], "intensity": [0, 0, 0]})
write('degenerate.json', sphere)

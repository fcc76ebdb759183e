"""Renders a glTF or OBJ scene with Blender Cycles the way `lightoctree reference`
renders it, so the project's path tracer can be judged against a production one
(docs/accuracy.md, "Against Blender Cycles").

Run it with Debian's Blender (3.4):

  blender -b --factory-startup -P tools/cycles_reference.py -- SCENE OUT.exr \
      [--width 256] [--height 192] [--spp 256] [--material gltf|principled|lambert]
      [--eye x,y,z --target x,y,z] [--fov DEG] [--bounces 16]

then `lightoctree compare ours.exr OUT.exr --bin 4 --ignore-background`.

What is matched (docs/scene.md defines the project's units):
  * lights: 1 cd = 1 W/sr and 1 lx = 1 W/m^2, so a point or spot light of
    intensity I gets Blender power 4 pi I W (Cycles gives a spot the intensity
    of the point light of its power), radius 0; a directional light strength I,
    angle 0. A spot is a hard Blender cone of the outer angle whose light
    shader applies glTF's squared falloff and divides out the cosine Cycles
    3.4 multiplies spots by;
  * emission: radiance = emissive colour x strength, from the front face only
    (the tracers' one-sided emitters): the back face's emission is switched
    off by the Backfacing output;
  * the sky (the scene's extras.lightoctree_sky): that radiance over the upper
    hemisphere, black below;
  * the film: linear scene values (view transform Standard, exposure 0), a
    1-pixel box filter, no denoising, no clamping, `--bounces` bounces;
  * the camera: the scene's first glTF camera (vertical field of view), or
    --eye/--target/--fov as `reference` takes them (glTF axes: +Y up).
Materials, --material:
  * principled: as Blender's importer makes them (Principled BSDF: Burley
    diffuse, GGX specular; not glTF's BRDF exactly);
  * gltf: glTF's BRDF built from nodes: Lambert diffuse times 1 - w F0 plus w
    times a GGX layer weighted by the Fresnel of each microfacet (a Principled
    BSDF with a black base: Cycles' dielectric Fresnel of l.h, F0 from
    KHR_materials_ior, w = KHR_materials_specular's specularFactor), and a GGX
    metal with F0 = the base colour (Principled, metallic 1), mixed by
    metallic. Not exact: glTF weights the diffuse lobe by 1 - w F(v.h), which
    no node sees (the constant is within 0.025 w of its mean), and Cycles'
    Smith shadowing is separable where glTF's is height-correlated;
  * lambert: the diffuse part alone (to judge the light transport apart from
    the material model).
"""

import argparse
import json
import math
import os
import sys

import numpy

# Blender 3.4's glTF importer calls numpy.bool, removed in NumPy 1.24.
if not hasattr(numpy, "bool"):
    numpy.bool = bool

import bpy  # noqa: E402
import mathutils  # noqa: E402


def parse_args():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    # "--target -0.1,0.2,0" as `reference` takes it: argparse would read the
    # value as an option.
    joined = []
    for a in argv:
        if joined and joined[-1] in ("--eye", "--target") and a.startswith("-"):
            joined[-1] += "=" + a
        else:
            joined.append(a)
    argv = joined
    p = argparse.ArgumentParser(prog="cycles_reference.py")
    p.add_argument("scene")
    p.add_argument("output")
    p.add_argument("--width", type=int, default=256)
    p.add_argument("--height", type=int, default=192)
    p.add_argument("--spp", type=int, default=256)
    p.add_argument("--material", choices=["gltf", "principled", "lambert"], default="gltf")
    p.add_argument("--eye")
    p.add_argument("--target")
    p.add_argument("--fov", type=float, default=0.0)
    p.add_argument("--bounces", type=int, default=16)
    p.add_argument("--seed", type=int, default=1)
    args = p.parse_args(argv)
    if (args.eye is None) != (args.target is None):
        p.error("--eye and --target must be given together")
    return args


def gltf_to_blender(v):
    """glTF (x, y, z), +Y up, to Blender's (x, -z, y), +Z up, as the importers map it."""
    return mathutils.Vector((v[0], -v[2], v[1]))


def read_gltf_json(path):
    if path.lower().endswith(".gltf"):
        with open(path) as f:
            return json.load(f)
    if path.lower().endswith(".glb"):
        with open(path, "rb") as f:
            data = f.read()
        length = int.from_bytes(data[12:16], "little")
        return json.loads(data[20:20 + length])
    return {}


def material_info(ior=1.5, weight=1.0, roughness=None, transmission=0.0, cutoff=None):
    """What the rebuilt material needs beyond Blender's import: the specular
    layer's F0 and weight, a roughness that overrides the import's (None:
    keep it), the transmission factor, and the alpha cutoff of MASK."""
    return {"ior": ior, "f0": ((ior - 1.0) / (ior + 1.0)) ** 2, "weight": weight,
            "roughness": roughness, "transmission": transmission, "cutoff": cutoff}


def read_obj_layers(path):
    """{material: material_info} as the project's OBJ loader
    maps the .mtl (docs/scene.md): Ks -> the layer's weight (its largest
    channel; none or 0: Lambertian, roughness 1), Ns -> roughness
    sqrt(2 / (Ns + 2)), Ni -> F0. Blender's importer maps them otherwise
    (roughness 1 - sqrt(Ns / 1000)), so they are set from here."""
    layers = {}
    folder = os.path.dirname(path)
    with open(path, errors="replace") as f:
        libs = [line.split(None, 1)[1].strip() for line in f if line.startswith("mtllib ")]
    for lib in libs:
        name, ks, ns, ni = None, 0.0, 0.0, 1.5

        def flush():
            if name is not None:
                weight = min(ks, 1.0)
                rough = math.sqrt(2.0 / (max(ns, 0.0) + 2.0)) if weight > 0 else 1.0
                layers[name] = material_info(ni, weight, rough)
        with open(os.path.join(folder, lib), errors="replace") as f:
            for line in f:
                words = line.split()
                if not words:
                    continue
                if words[0] == "newmtl":
                    flush()
                    name, ks, ns, ni = " ".join(words[1:]), 0.0, 0.0, 1.5
                elif words[0] == "Ks":
                    ks = max(float(w) for w in words[1:4])
                elif words[0] == "Ns":
                    ns = float(words[1])
                elif words[0] == "Ni" and float(words[1]) > 0:
                    ni = float(words[1])
        flush()
    return layers


def import_scene(path):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    lower = path.lower()
    if lower.endswith(".gltf") or lower.endswith(".glb"):
        bpy.ops.import_scene.gltf(filepath=path)
    elif lower.endswith(".obj"):
        # The OBJ is +Y up like glTF: the importer turns it to Blender's +Z up.
        bpy.ops.wm.obj_import(filepath=path, forward_axis="NEGATIVE_Z", up_axis="Y")
    else:
        sys.exit("cycles_reference.py: SCENE must be .gltf, .glb or .obj: " + path)


def set_lights(gltf):
    """Blender power from the glTF intensities (the importer's conversion is
    photometric; the project's is radiometric)."""
    lights = gltf.get("extensions", {}).get("KHR_lights_punctual", {}).get("lights", [])
    by_name = {l.get("name", ""): l for l in lights}
    for obj in bpy.context.scene.objects:
        if obj.type != "LIGHT":
            continue
        data = obj.data
        name = data.name.split(".")[0]
        g = by_name.get(name)
        if g is None and len(lights) == 1:
            g = lights[0]
        if g is None:
            print("cycles_reference.py: no glTF light named '%s'; left as imported" % name)
            continue
        colour = g.get("color", [1, 1, 1])
        intensity = g.get("intensity", 1.0)
        data.color = colour
        if g["type"] == "directional":
            data.energy = intensity
            data.angle = 0.0
        else:
            data.energy = 4.0 * math.pi * intensity
            data.shadow_soft_size = 0.0
            if g["type"] == "spot":
                spot = g.get("spot", {})
                outer = spot.get("outerConeAngle", math.pi / 4)
                inner = spot.get("innerConeAngle", 0.0)
                glTF_spot_falloff(obj, outer, inner)


def glTF_spot_falloff(obj, outer, inner):
    """A hard Blender cone of the outer angle whose emission carries glTF's
    falloff ((cos - cosOuter) / (cosInner - cosOuter))^2 divided by the
    cosine Cycles 3.4 multiplies a spot's intensity by (its spot
    attenuation returns dot(direction, axis) inside the cone), from the
    direction the light shader sees (Texture Coordinate > Normal)."""
    data = obj.data
    data.spot_size = 2.0 * outer
    data.spot_blend = 0.0
    data.use_nodes = True
    tree = data.node_tree
    emission = next(n for n in tree.nodes if n.type == "EMISSION")
    axis = obj.matrix_world.to_3x3() @ mathutils.Vector((0.0, 0.0, -1.0))
    axis.normalize()
    coords = tree.nodes.new("ShaderNodeTexCoord")
    along = tree.nodes.new("ShaderNodeVectorMath")
    along.operation = "DOT_PRODUCT"
    along.inputs[1].default_value = axis
    tree.links.new(coords.outputs["Normal"], along.inputs[0])
    cosine = tree.nodes.new("ShaderNodeMath")
    cosine.operation = "ABSOLUTE"
    tree.links.new(along.outputs["Value"], cosine.inputs[0])
    cos_o, cos_i = math.cos(outer), math.cos(inner)
    ramp = tree.nodes.new("ShaderNodeMapRange")  # clamp((c - cosO) / (cosI - cosO), 0, 1)
    ramp.inputs["From Min"].default_value = cos_o
    ramp.inputs["From Max"].default_value = max(cos_i, cos_o + 1e-6)
    ramp.clamp = True
    tree.links.new(cosine.outputs["Value"], ramp.inputs["Value"])
    square = tree.nodes.new("ShaderNodeMath")
    square.operation = "MULTIPLY"
    tree.links.new(ramp.outputs["Result"], square.inputs[0])
    tree.links.new(ramp.outputs["Result"], square.inputs[1])
    strength = tree.nodes.new("ShaderNodeMath")
    strength.operation = "DIVIDE"
    tree.links.new(square.outputs["Value"], strength.inputs[0])
    tree.links.new(cosine.outputs["Value"], strength.inputs[1])
    tree.links.new(strength.outputs["Value"], emission.inputs["Strength"])


def socket_value(socket):
    """(linked output socket or None, default value) of an input socket."""
    if socket.is_linked:
        return socket.links[0].from_socket, None
    return None, socket.default_value


def connect(tree, source, default, target):
    if source is not None:
        tree.links.new(source, target)
    elif default is not None:
        try:
            target.default_value = default
        except (TypeError, ValueError):
            target.default_value = default[0] if hasattr(default, "__len__") else default


def principled_lobe(tree, base, metallic, specular, rough_src, rough_val):
    """A Principled BSDF reduced to its GGX specular lobe: Cycles 3.4 weights
    it by the Fresnel of each microfacet, interpolated from F0 (0.08 x
    specular, or the base colour when metallic) to 1 as glTF's Schlick term is."""
    node = tree.nodes.new("ShaderNodeBsdfPrincipled")
    node.distribution = "GGX"
    if base is not None:
        node.inputs["Base Color"].default_value = base
    node.inputs["Metallic"].default_value = metallic
    node.inputs["Specular"].default_value = specular
    node.inputs["Specular Tint"].default_value = 0.0
    node.inputs["Sheen"].default_value = 0.0
    node.inputs["Clearcoat"].default_value = 0.0
    node.inputs["Subsurface"].default_value = 0.0
    node.inputs["Transmission"].default_value = 0.0
    connect(tree, rough_src, rough_val, node.inputs["Roughness"])
    return node


def rebuild_material(mat, mode, layer_of):
    """Replaces the material's Principled BSDF by glTF's BRDF from nodes (gltf)
    or its diffuse part (lambert); in every mode, emission from the front face
    only."""
    if not mat.use_nodes:
        return
    tree = mat.node_tree
    principled = next((n for n in tree.nodes if n.type == "BSDF_PRINCIPLED"), None)
    output = next((n for n in tree.nodes if n.type == "OUTPUT_MATERIAL"), None)
    if principled is None or output is None:
        return
    base_src, base_val = socket_value(principled.inputs["Base Color"])
    metal_src, metal_val = socket_value(principled.inputs["Metallic"])
    rough_src, rough_val = socket_value(principled.inputs["Roughness"])
    normal_src, _ = socket_value(principled.inputs["Normal"])
    em_src, em_val = socket_value(principled.inputs["Emission"])
    em_strength = principled.inputs["Emission Strength"].default_value
    emits = em_src is not None or (em_val is not None and max(em_val[:3]) * em_strength > 0)

    surface = principled.outputs["BSDF"]
    if mode in ("gltf", "lambert"):
        diffuse = tree.nodes.new("ShaderNodeBsdfDiffuse")
        connect(tree, base_src, base_val, diffuse.inputs["Color"])
        diffuse.inputs["Roughness"].default_value = 0.0  # Lambert
        if normal_src is not None:
            tree.links.new(normal_src, diffuse.inputs["Normal"])
        surface = diffuse.outputs["BSDF"]
    info = layer_of(mat)
    f0, weight = info["f0"], info["weight"]
    if info["roughness"] is not None:
        rough_src, rough_val = None, info["roughness"]
    alpha_src, alpha_val = socket_value(principled.inputs["Alpha"])
    if mode == "gltf":
        # Diffuse weight 1 - w F(v.h): constant 1 - w F0 here (no node sees
        # v.h for a diffuse lobe); the cosine-weighted mean of F(v.h) exceeds
        # F0 by at most 0.025 w, at grazing view. A Fresnel node on n.v would
        # give 1 - F(n.v), 0.22 at grazing where glTF's mean is 0.94.
        darken = tree.nodes.new("ShaderNodeMixRGB")
        darken.blend_type = "MULTIPLY"
        darken.inputs["Fac"].default_value = 1.0
        connect(tree, base_src, base_val, darken.inputs["Color1"])
        keep = 1.0 - weight * f0
        darken.inputs["Color2"].default_value = (keep, keep, keep, 1.0)
        tree.links.new(darken.outputs["Color"], diffuse.inputs["Color"])
        # The layer w F(v.h) GGX: a Principled BSDF with a black base is its
        # GGX lobe alone, with the Fresnel of each microfacet (l.h = v.h),
        # F0 = 0.08 specular, untinted.
        layer = principled_lobe(tree, (0.0, 0.0, 0.0, 1.0), 0.0, f0 / 0.08, rough_src, rough_val)
        scaled = tree.nodes.new("ShaderNodeMixShader")  # w x layer
        scaled.inputs[0].default_value = weight
        nothing = tree.nodes.new("ShaderNodeBsdfDiffuse")
        nothing.inputs["Color"].default_value = (0.0, 0.0, 0.0, 1.0)
        tree.links.new(nothing.outputs["BSDF"], scaled.inputs[1])
        tree.links.new(layer.outputs["BSDF"], scaled.inputs[2])
        dielectric = tree.nodes.new("ShaderNodeAddShader")
        tree.links.new(diffuse.outputs["BSDF"], dielectric.inputs[0])
        tree.links.new(scaled.outputs["Shader"], dielectric.inputs[1])
        if info["transmission"] > 0:
            # KHR_materials_transmission: the diffuse base gives way to a
            # GGX BTDF under the same Fresnel layer: a Glass BSDF (its exact
            # Fresnel splits reflection and refraction), tinted by the base.
            glass = tree.nodes.new("ShaderNodeBsdfGlass")
            glass.distribution = "GGX"
            glass.inputs["IOR"].default_value = info["ior"]
            connect(tree, base_src, base_val, glass.inputs["Color"])
            connect(tree, rough_src, rough_val, glass.inputs["Roughness"])
            if normal_src is not None:
                tree.links.new(normal_src, glass.inputs["Normal"])
            transmits = tree.nodes.new("ShaderNodeMixShader")
            transmits.inputs[0].default_value = info["transmission"]
            tree.links.new(dielectric.outputs["Shader"], transmits.inputs[1])
            tree.links.new(glass.outputs["BSDF"], transmits.inputs[2])
            dielectric = transmits
        # The metal: the same lobe with F0 = the base colour (metallic 1).
        metal = principled_lobe(tree, None, 1.0, 0.5, rough_src, rough_val)
        connect(tree, base_src, base_val, metal.inputs["Base Color"])
        if normal_src is not None:
            for n in (layer, metal):
                tree.links.new(normal_src, n.inputs["Normal"])
        mix = tree.nodes.new("ShaderNodeMixShader")
        connect(tree, metal_src, metal_val, mix.inputs[0])
        tree.links.new(dielectric.outputs["Shader"], mix.inputs[1])
        tree.links.new(metal.outputs["BSDF"], mix.inputs[2])
        surface = mix.outputs["Shader"]
    if emits:
        # Emission from the front face only, added to the surface.
        principled.inputs["Emission Strength"].default_value = 0.0
        emission = tree.nodes.new("ShaderNodeEmission")
        connect(tree, em_src, em_val, emission.inputs["Color"])
        emission.inputs["Strength"].default_value = em_strength
        black = tree.nodes.new("ShaderNodeEmission")
        black.inputs["Strength"].default_value = 0.0
        geometry = tree.nodes.new("ShaderNodeNewGeometry")
        front = tree.nodes.new("ShaderNodeMixShader")
        tree.links.new(geometry.outputs["Backfacing"], front.inputs[0])
        tree.links.new(emission.outputs["Emission"], front.inputs[1])
        tree.links.new(black.outputs["Emission"], front.inputs[2])
        add = tree.nodes.new("ShaderNodeAddShader")
        tree.links.new(surface, add.inputs[0])
        tree.links.new(front.outputs["Shader"], add.inputs[1])
        surface = add.outputs["Shader"]
    if alpha_src is not None or (alpha_val is not None and alpha_val < 1.0):
        # Coverage: alpha (BLEND) or alpha < cutoff cut away (MASK), as the
        # tracers read glTF's alphaMode.
        coverage_src = alpha_src
        if info["cutoff"] is not None:
            opaque = tree.nodes.new("ShaderNodeMath")
            opaque.operation = "GREATER_THAN"
            connect(tree, alpha_src, alpha_val, opaque.inputs[0])
            opaque.inputs[1].default_value = info["cutoff"] - 1e-6
            coverage_src = opaque.outputs["Value"]
        transparent = tree.nodes.new("ShaderNodeBsdfTransparent")
        covered = tree.nodes.new("ShaderNodeMixShader")
        connect(tree, coverage_src, alpha_val if coverage_src is None else None, covered.inputs[0])
        tree.links.new(transparent.outputs["BSDF"], covered.inputs[1])
        tree.links.new(surface, covered.inputs[2])
        surface = covered.outputs["Shader"]
    tree.links.new(surface, output.inputs["Surface"])


def set_world(gltf):
    world = bpy.data.worlds.new("sky")
    bpy.context.scene.world = world
    world.use_nodes = True
    tree = world.node_tree
    background = next(n for n in tree.nodes if n.type == "BACKGROUND")
    scenes = gltf.get("scenes", [])
    index = gltf.get("scene", 0)
    sky = None
    if 0 <= index < len(scenes):
        sky = scenes[index].get("extras", {}).get("lightoctree_sky")
    if not sky:
        background.inputs["Strength"].default_value = 0.0
        return
    # The sky's radiance above the horizon (Blender +Z), black below.
    coords = tree.nodes.new("ShaderNodeTexCoord")
    split = tree.nodes.new("ShaderNodeSeparateXYZ")
    above = tree.nodes.new("ShaderNodeMath")
    above.operation = "GREATER_THAN"
    above.inputs[1].default_value = 0.0
    tree.links.new(coords.outputs["Generated"], split.inputs[0])
    tree.links.new(split.outputs["Z"], above.inputs[0])
    background.inputs["Color"].default_value = (sky[0], sky[1], sky[2], 1.0)
    tree.links.new(above.outputs["Value"], background.inputs["Strength"])


def set_camera(args, gltf):
    scene = bpy.context.scene
    if args.eye is not None:
        eye = gltf_to_blender([float(x) for x in args.eye.split(",")])
        target = gltf_to_blender([float(x) for x in args.target.split(",")])
        data = bpy.data.cameras.new("view")
        cam = bpy.data.objects.new("view", data)
        scene.collection.objects.link(cam)
        cam.location = eye
        cam.rotation_euler = (target - eye).to_track_quat("-Z", "Y").to_euler()
        data.sensor_fit = "VERTICAL"
        data.angle_y = math.radians(args.fov if args.fov > 0 else 45.0)
        scene.camera = cam
        return
    cams = [o for o in scene.objects if o.type == "CAMERA"]
    if not cams:
        sys.exit("cycles_reference.py: the scene has no camera: give --eye and --target")
    cam = sorted(cams, key=lambda o: o.name)[0]
    scene.camera = cam
    yfov = None
    for c in gltf.get("cameras", []):
        if c.get("type") == "perspective":
            yfov = c["perspective"]["yfov"]
            break
    if args.fov > 0:
        yfov = math.radians(args.fov)
    if yfov is not None:
        cam.data.sensor_fit = "VERTICAL"
        cam.data.angle_y = yfov


def main():
    args = parse_args()
    scene_path = os.path.abspath(args.scene)
    gltf = read_gltf_json(scene_path)
    import_scene(scene_path)
    set_lights(gltf)
    layers = {}
    for m in gltf.get("materials", []):
        ext = m.get("extensions", {})
        layers[m.get("name", "")] = material_info(
            ior=ext.get("KHR_materials_ior", {}).get("ior", 1.5),
            weight=ext.get("KHR_materials_specular", {}).get("specularFactor", 1.0),
            transmission=ext.get("KHR_materials_transmission", {}).get("transmissionFactor", 0.0),
            cutoff=m.get("alphaCutoff", 0.5) if m.get("alphaMode") == "MASK" else None)
    if scene_path.lower().endswith(".obj"):
        layers = read_obj_layers(scene_path)
    for mat in bpy.data.materials:
        rebuild_material(mat, args.material,
                         lambda m: layers.get(m.name.split(".")[0], material_info()))
    set_world(gltf)
    set_camera(args, gltf)

    scene = bpy.context.scene
    scene.render.engine = "CYCLES"
    scene.cycles.device = "CPU"
    scene.cycles.samples = args.spp
    scene.cycles.use_adaptive_sampling = False
    scene.cycles.use_denoising = False
    scene.cycles.seed = args.seed
    scene.cycles.max_bounces = args.bounces
    for kind in ("diffuse", "glossy", "transmission", "transparent", "volume"):
        setattr(scene.cycles, kind + "_bounces", args.bounces)
    scene.cycles.sample_clamp_direct = 0.0
    scene.cycles.sample_clamp_indirect = 0.0
    scene.cycles.blur_glossy = 0.0
    scene.cycles.caustics_reflective = True
    scene.cycles.caustics_refractive = True
    scene.cycles.pixel_filter_type = "BOX"
    scene.cycles.filter_width = 1.0
    scene.render.resolution_x = args.width
    scene.render.resolution_y = args.height
    scene.render.resolution_percentage = 100
    scene.render.film_transparent = False
    scene.view_settings.view_transform = "Standard"
    scene.view_settings.look = "None"
    scene.view_settings.exposure = 0.0
    scene.view_settings.gamma = 1.0
    scene.render.image_settings.file_format = "OPEN_EXR"
    scene.render.image_settings.color_depth = "32"
    scene.render.image_settings.color_mode = "RGB"
    scene.render.filepath = os.path.abspath(args.output)
    bpy.ops.render.render(write_still=True)
    image = bpy.data.images.load(os.path.abspath(args.output))
    pixels = numpy.array(image.pixels[:]).reshape(-1, 4)[:, :3]
    mean = pixels.mean(axis=0)
    print("cycles_reference.py: wrote %s (%d x %d, %d spp, materials: %s); mean RGB %.6g %.6g %.6g" %
          (args.output, args.width, args.height, args.spp, args.material, mean[0], mean[1], mean[2]))


main()

# EEVEE and Cycles set to draw a bake as the project's renderer does: the
# lamps' direct light from Blender, the indirect light (and all of the sky's
# light, which the bake holds) from the lightmap pages, nothing twice.
from .lightmap import PREFIX


def setup(scene):
    """Cycles traces no diffuse bounce of its own (the pages hold them) and
    the World lights nothing, showing itself to the camera only (the bake
    holds the sky's light); EEVEE, which has no indirect light without its
    own light cache, needs only the second. Returns what changed, as words."""
    changed = []
    if scene.cycles.diffuse_bounces != 0:
        scene.cycles.diffuse_bounces = 0
        changed.append("Cycles diffuse bounces 0")
    if scene.world is not None and _sky_for_the_camera_only(scene.world):
        changed.append(f"World '{scene.world.name}' seen by the camera only")
    return changed


def _sky_for_the_camera_only(world):
    """Puts a Mix Shader (Light Path: Is Camera Ray) between the World's
    shader and its output, black for every other ray; False when there
    already is one."""
    if not world.use_nodes:
        colour = tuple(world.color)
        world.use_nodes = True
        background = next(n for n in world.node_tree.nodes if n.type == "BACKGROUND")
        background.inputs["Color"].default_value = (*colour, 1.0)
        background.inputs["Strength"].default_value = 1.0
    tree = world.node_tree
    output = next((n for n in tree.nodes if n.type == "OUTPUT_WORLD" and n.is_active_output), None)
    if output is None or not output.inputs["Surface"].is_linked:
        return False
    shader = output.inputs["Surface"].links[0].from_node
    if shader.name.startswith(PREFIX):
        return False
    path = tree.nodes.new("ShaderNodeLightPath")
    dark = tree.nodes.new("ShaderNodeBackground")
    dark.inputs["Strength"].default_value = 0.0
    mix = tree.nodes.new("ShaderNodeMixShader")
    for node, label, offset in ((path, "Light Octree: the sky is baked", (-250, 250)),
                                (dark, "lights nothing", (-250, -150)), (mix, "", (-20, 0))):
        node.name, node.label = f"{PREFIX} {node.bl_label}", label
        node.location = (output.location.x + offset[0], output.location.y + offset[1])
    output.location.x += 200
    tree.links.new(path.outputs["Is Camera Ray"], mix.inputs[0])
    tree.links.new(dark.outputs[0], mix.inputs[1])
    tree.links.new(output.inputs["Surface"].links[0].from_socket, mix.inputs[2])
    tree.links.new(mix.outputs[0], output.inputs["Surface"])
    return True

"""Cache -> Blender data builders (bpy side)."""

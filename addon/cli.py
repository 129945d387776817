"""`python -m addon.cli`: the command line, whose code is on the Blender side (`blender.cli`)
because it reads the .blend through bpy."""
import sys

from .blender.cli import main

if __name__ == "__main__":
    sys.exit(main())

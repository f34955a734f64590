"""``python -m plume.job run <cache folder or job file>``: one Plume job without Blender (the
child each long operator starts, and what a farm runs); see jobs/child.py."""

import sys

from .jobs.child import main

if __name__ == "__main__":
    sys.exit(main())

"""``slide_probes_mjx.py`` (the rim, press and strike probes of our Slide) with the pad-puck friction changed first
(``slide_fingers.PAD_PUCK_CONTACT``'s, no task option holds it).

    PYTHONPATH=. python experiments/results/2026-11-28/slide-pads-contact/traces/probes_friction.py 0.2 \
        --env-options finger=pads,finger_table=1,drive=weld,gripper_mass=22 --strike 200 --out OUT.json
"""

import os
import runpy
import sys

from envs.fetch import slide_fingers

PROBES = os.path.join(os.path.dirname(os.path.abspath(__file__)), *[".."] * 2, "slide-pads", "analysis",
                      "slide_probes_mjx.py")  # fmt: skip

if __name__ == "__main__":
    mu = float(sys.argv[1])
    slide_fingers.PAD_PUCK_CONTACT = slide_fingers.PAD_PUCK_CONTACT.replace('friction="1 1 ', f'friction="{mu} {mu} ')
    sys.argv = [PROBES, *sys.argv[2:]]
    runpy.run_path(PROBES, run_name="__main__")

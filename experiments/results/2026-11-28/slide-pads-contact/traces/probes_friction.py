"""``slide_probes_mjx.py`` (the rim, press and strike probes of our Slide) with the pad-puck friction changed first
(``slide_fingers.PAD_PUCK_CONTACT``'s; the task option ``pad_friction`` came after).

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
    contact = slide_fingers.PAD_PUCK_CONTACT
    slide_fingers.PAD_PUCK_CONTACT = contact.replace('friction="{mu} {mu} ', f'friction="{mu} {mu} ')
    sys.argv = [PROBES, *sys.argv[2:]]
    runpy.run_path(PROBES, run_name="__main__")

"""Where each never-reached episode of Push ends in our simulator: the cube's distance to the goal, the grip's across
and above the cube, and the last action.

    python never_reached.py TRACES.npz...
"""

import sys

import numpy as np

for path in sys.argv[1:]:
    t = np.load(path)
    obs, goal, success, actions = t["ours_obs"], t["goal_ours"], t["ours_success"], t["ours_actions"]
    print(path.split("/")[-1])
    for i in np.where(~success.any(1))[0]:
        cube, grip = obs[i, -1, 3:6], obs[i, -1, 0:3]
        print(f"  episode {i:3d}: cube to goal {np.linalg.norm((goal[i] - cube)[:2]):.3f}, grip across "
              f"{np.linalg.norm((grip - cube)[:2]):.3f}, above {grip[2] - cube[2]:+.3f}, last action "
              f"{np.round(actions[i, -1], 2)}")

"""
A bump response
===============

The half car of ``suspopt init half_pitch`` over its bump.
"""

import matplotlib.pyplot as plt

import suspopt

cfg = suspopt.load_template("half_pitch")
res = suspopt.simulate(cfg)
fig, ax = plt.subplots()
ax.plot(res.time, res.signals["body.heave_acc"][0])

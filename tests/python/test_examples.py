"""The Python examples, run as their READMEs say: primes against a sieve, the wind against the
analytic drag response."""

import json
import shutil
from pathlib import Path

import numpy as np

from conftest import run

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


def test_python_primes_finds_every_prime_below_the_blocks_it_covered(tmp_path):
    folder = tmp_path / "python_primes"
    shutil.copytree(EXAMPLES / "python_primes", folder)
    result = run(tmp_path, folder / "primes.xml", "--iterations", "4")
    assert result.code == 0, result.stderr
    found = np.loadtxt(tmp_path / "primes.txt", dtype=np.int64)
    limit = 4 * 3 * 10000  # iterations x workers x block
    sieve = np.ones(limit, dtype=bool)
    sieve[:2] = False
    for p in range(2, int(limit ** 0.5) + 1):
        if sieve[p]:
            sieve[p * p::p] = False
    assert found.tolist() == np.flatnonzero(sieve).tolist()
    # The merge summed the workers' counts: the visu's last line names this iteration's share.
    last = result.log("visu").strip().splitlines()[-1]
    assert f"{len(found)} primes, largest {int(found[-1])}" in last
    share = np.count_nonzero(sieve[3 * 3 * 10000:])
    assert f"{share} new" in last


def test_python_wind_drives_a_free_body_to_the_wind_speed_like_linear_drag(tmp_path):
    """One sphere without gravity in a steady wind w: m dv/dt = c (w - v). The rigid animator
    steps with explicit forces: iteration n integrates the force the wind computed from the state
    of iteration n - 1 over dt, so after k steps v = w (1 - (1 - c dt / m)^k) (the exact
    solution of the discrete system), which tends to the analytic w (1 - exp(-c t / m))."""
    folder = tmp_path / "python_wind"
    shutil.copytree(EXAMPLES / "python_wind", folder)
    mass, drag, wind, dt, steps = 2.0, 4.0, 3.0, 0.01, 60
    scene = {"bodies": [{"shape": {"type": "sphere", "radius": 0.1}, "mass": mass,
                         "position": [0, 1, 0]}]}
    (tmp_path / "scene.json").write_text(json.dumps(scene))
    app = tmp_path / "wind.xml"
    app.write_text(f"""<?xml version="1.0" encoding="UTF-8"?>
<application name="wind-drag" version="1">
  <packages path="{folder}"/>
  <modules>
    <module id="bodies" package="rigid" type="animator">
      <param name="scene" value="{tmp_path / 'scene.json'}"/>
      <param name="dt" value="{dt}"/>
      <param name="sleep" value="false"/>
      <param name="state-file" value="{tmp_path / 'final.json'}"/>
      <input port="events" initial-messages="1"/>
    </module>
    <module id="wind" package="pywind" type="wind">
      <param name="velocity" value="{wind} 0 0"/>
      <param name="gust" value="0"/>
      <param name="drag" value="{drag}"/>
    </module>
  </modules>
  <connections>
    <connection from="bodies.objects" to="wind.objects"/>
    <connection from="wind.forces" to="bodies.events"/>
  </connections>
</application>
""")
    result = run(tmp_path, app, "--iterations", str(steps))
    assert result.code == 0, result.stderr
    final = json.loads((tmp_path / "final.json").read_text())
    steps_done = final["steps"]
    assert steps_done == steps - 1  # iteration 0 sends the scene without stepping
    v = final["bodies"][0]["linearVelocity"]
    discrete = wind * (1 - (1 - dt * drag / mass) ** steps_done)
    analytic = wind * (1 - np.exp(-drag / mass * steps_done * dt))
    assert abs(v[0] - discrete) < 1e-9 * wind, (v, discrete, analytic)
    assert abs(v[0] - analytic) < 0.01 * wind
    assert abs(v[1]) < 1e-12 and abs(v[2]) < 1e-12

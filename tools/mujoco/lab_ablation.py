"""Which of the lab's numbers make `mugatu-lab` walk: each group of its values replaced by the
bundled `mugatu`'s, one group at a time, and walked (25 s, the design's own drive).

    python tools/mujoco/lab_ablation.py        # a Markdown table (reports/lab-models.md)

Needs only the two bundled design files and the `survey` binary ($SURVEY, else target/debug).
"""

from __future__ import annotations

import json
import os
import re
import subprocess
import tempfile

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
SURVEY = os.environ.get("SURVEY") or os.path.join(ROOT, "target", "debug", "survey")

# (what the bundled mugatu has instead, [(key, bundled value)]); a key absent from the lab
# file is added to its section.
GROUPS = [
    ("feet: half spheres cut at the mid-plane, centred under the hip",
     [("geometry", "foot_center_lateral_over_l", "0.0"), ("geometry", "foot_center_forward_over_l", "0.0"),
      ("geometry", "foot_section_cut_over_l", "0.0")]),
    ("mass distribution: COM 0.45 L, legs at ±0.2 L, box [1.2, 0.2, 1.0] L, no forward offset",
     [("mass", "leg_com_height_over_l", "0.45"), ("geometry", "hip_half_width_over_l", "0.2"),
      ("mass", "leg_inertia_box_over_l", "[1.2, 0.2, 1.0]"), ("mass", "leg_com_forward_over_l", "0.0")]),
    ("contact: μ 0.35, Hunt–Crossley 50 s/m",
     [("contact", "friction_mu", "0.35"), ("contact", "relaxation_time_s", "0.0"),
      ("contact", "hunt_crossley_dissipation_s_per_m", "50.0")]),
    ("drive: 25° at 1.24 Hz, kp 20, kd 2 (per m·g·L)",
     [("control", "amplitude_deg", "25.0"), ("control", "frequency_hz", "1.24"),
      ("control", "kp_over_mgl", "20.0"), ("control", "kd_over_mgl_sqrt_l_over_g", "2.0")]),
]


def set_value(text: str, section: str, key: str, value: str) -> str:
    pat = re.compile(r"^(" + re.escape(key) + r"\s*=\s*)[^#\n]+", re.M)
    if pat.search(text):
        return pat.sub(lambda m: m.group(1) + value + "  ", text, count=1)
    return text.replace(f"[{section}]\n", f"[{section}]\n{key} = {value}\n", 1)


def walk(text: str) -> dict:
    with tempfile.NamedTemporaryFile("w", suffix=".toml", delete=False) as f:
        f.write(text)
    try:
        out = subprocess.run([SURVEY, "sim", "walk", "--design", f.name, "--format", "json"],
                             check=True, capture_output=True, text=True).stdout
    finally:
        os.unlink(f.name)
    return json.loads(out)


def row(name: str, r: dict) -> str:
    def c(k):
        v = r.get(k)
        return "—" if v is None else f"{v:.3g}"
    status = f"fell ({r['fall_reason']})" if r.get("fall_reason") else ("yes" if r["walks"] else "no")
    return (f"| {name} | {status} | {c('velocity_mps')} | {c('roll_pp_deg')} | {c('pitch_pp_deg')} "
            f"| {c('yaw_pp_deg')} |")


def main():
    lab = open(os.path.join(ROOT, "dataset", "walkers", "mugatu-lab.toml")).read()
    print("| mugatu-lab with the bundled mugatu's … | walks | v [m/s] | roll p-p [°] | pitch p-p [°] | yaw p-p [°] |")
    print("|---|---|---|---|---|---|")
    print(row("(nothing: the lab's numbers)", walk(lab)))
    for name, values in GROUPS:
        text = lab
        for section, key, value in values:
            text = set_value(text, section, key, value)
        print(row(name, walk(text)))


if __name__ == "__main__":
    main()

"""A rigid symmetric rotor with a disk at mid-span, as a rig file's text, and its mass and
inertias by hand (tests of gyroscopic closed forms)."""

from __future__ import annotations

import math
from pathlib import Path

#: a shaft 1e4 times stiffer than steel: its bending, under support forces and inertia up
#: to a few hundred hertz, adds below 1e-6 of the rigid rotor's response
E_RIGID = 2.1e15
RHO = 7850.0
L, D = 0.4, 0.1


def rotor_text(name: str, disk_m: float, disk_ip: float, disk_id: float,
               elements: int, disk_z: float = L / 2, modal_damping: float = 0.0) -> str:
    """``[rotor]``, the material, the shaft (L × D) in ``elements`` and the disk at
    ``disk_z`` (m; mid-span by default); the supports are the caller's. ``modal_damping``
    damps the stiff shaft's bending modes (hundreds of kHz), which a loop with a sampled
    controller's delay would otherwise find undamped."""
    damping = f"modal_damping = {modal_damping}\n" if modal_damping else ""
    return f"""
[rotor]
name = "{name}"
{damping}[materials.rigid]
E = {E_RIGID}
rho = {RHO}
nu = 0.3
[[shaft]]
length = {L}
outer_diameter = {D}
material = "rigid"
elements = {elements}
[[disk]]
position = {disk_z}
mass = {disk_m}
Ip = {disk_ip}
Id = {disk_id}
"""


def inertia(disk_m: float, disk_ip: float, disk_id: float) -> tuple[float, float, float]:
    """(m, I_t about the centre, I_p) of the shaft (a solid cylinder) and the disk."""
    ms = RHO * math.pi / 4 * D**2 * L
    return (ms + disk_m, ms * (3 * (D / 2) ** 2 + L**2) / 12 + disk_id,
            ms * (D / 2) ** 2 / 2 + disk_ip)


def rigid_amb_rig(tmp_path, disk_ip: float = 0.4, bias_a: float = 2.5) -> Path:
    """A rigid rotor (shaft 1e4 times stiffer than steel) with a disk of polar inertia
    ``disk_ip`` (0.4 kg·m²: Ip/It 0.79 about the centre of mass), on two AMBs of bias
    current ``bias_a`` (A), run 133–400 Hz, sampled at 20 kHz with one sample of delay."""
    text = rotor_text("rigid gyroscopic rotor", 20.0, disk_ip, 0.2, 4, modal_damping=0.01)
    for name, z in (("A", 0.05), ("B", L - 0.05)):
        text += (f'[[amb]]\nname = "{name}"\nposition = {z}\nsensor_position = {z}\n'
                 f"ki = 200.0\nks = 1.0e6\nbias_current = {bias_a}\ncurrent_limit = 5.0\n"
                 "air_gap = 5.0e-4\n")
    text += ('[actuator]\nmodel = "first_order"\ncutoff_hz = 2000.0\n'
             "[controller]\nsample_rate_hz = 20000.0\ndelay_samples = 1\n"
             "[operating]\nspeed_rpm = 24000.0\npressure_bar = 0.0\n"
             "speed_range_hz = [133.3, 400.0]\n")
    path = tmp_path / "rigid_rotor.toml"
    path.write_text(text)
    return path

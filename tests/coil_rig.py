"""A small rig on two AMBs that gives its coils both ways — the inductance and the geometry
(turns, pole area, air gap) — with a resistance, a supply voltage and a current limit, and
a continuous speed range of 400–600 Hz (30 000 rpm nominal): a disc-like rotor (Ip > Id)
whose worst unbalance orbit lies below the range, where it runs up. No seal; the PID is
derived from the rig."""

COIL_RIG = """
[rotor]
name = "coil rig"
modal_damping = 0.01
[materials.steel]
E = 2.1e11
rho = 7850.0
nu = 0.3
[[shaft]]
length = 0.4
outer_diameter = 0.06
material = "steel"
elements = 8
[[disk]]
position = 0.2
mass = 8.0
Ip = 0.04
Id = 0.025
[[amb]]
name = "A"
position = 0.05
sensor_position = 0.03
turns = 120
pole_area = 4.0e-4
air_gap = 5.0e-4
bias_current = 3.0
inductance = 0.012
resistance = 0.5
supply_voltage = 150.0
current_limit = 6.0
backup_clearance = 2.5e-4
[[amb]]
name = "B"
position = 0.35
sensor_position = 0.37
turns = 120
pole_area = 4.0e-4
air_gap = 5.0e-4
bias_current = 3.0
inductance = 0.012
resistance = 0.5
supply_voltage = 150.0
current_limit = 6.0
backup_clearance = 2.5e-4
[operating]
speed_rpm = 30000.0
speed_range_hz = [400.0, 600.0]
"""

"""Physical constants and the seed-000 (Table 4.1) data, in SI units."""

G0 = 9.81
"""Constant gravity of seed 000 (Table 4.1, Sec. 2.1 assumption 3), m/s^2."""

MU_EARTH = 3.986004418e14
"""Earth's gravitational parameter, m^3/s^2 (not in seed 000; used for inverse-square gravity and orbits)."""

R_EARTH_000 = 6378.1e3
"""Earth radius of seed 000 (Table 4.1), m."""

# Seed 000, Table 4.1: exponential atmosphere and vehicle.
RHO_S_000 = 1.752
"""Base density of seed 000, kg/m^3 (Table 4.1)."""
H_SCALE_000 = 7045.0
"""Density scale height of seed 000, m (Table 4.1)."""
CD0_000 = 0.1
"""Parasite drag coefficient of seed 000 (Table 4.1)."""
M_OVER_S_000 = 300.0
"""Mass over reference area of seed 000, kg/m^2 (Table 4.1)."""

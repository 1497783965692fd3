#!/usr/bin/python3
"""Local sampling of the raw lens relative to the rectified pinhole (same f = 640 px), left
cameras' calibrations of the generated rigs: radial d r_raw / d r_pin and tangential r_raw / r_pin
as a function of the normalized radius rho = tan(theta) of the rectified image."""
import numpy as np
k_rt = [-0.28, 0.074]                      # radtan D1 (k1, k2; p1, p2 ~ 0)
k_eq = [-0.013, 0.004, -0.002, 0.0004]     # equidistant D1 (k1..k4)
print("| rho = \\|x\\| (normalized) | radtan radial | radtan tangential | equidistant radial | equidistant tangential |")
print("|---|---|---|---|---|")
for rho in [0.0, 0.2, 0.4, 0.6, 0.8, 1.0, 1.15]:
    h = 1e-6
    def rt(r): return r * (1 + k_rt[0]*r**2 + k_rt[1]*r**4)
    def eq(r):
        th = np.arctan(r); return th * (1 + k_eq[0]*th**2 + k_eq[1]*th**4 + k_eq[2]*th**6 + k_eq[3]*th**8)
    def rad(f, r): return (f(r+h) - f(max(r-h, 0))) / (r+h - max(r-h, 0))
    def tan(f, r): return f(r)/r if r > 0 else rad(f, 0)
    print(f"| {rho:.2f} | {rad(rt,rho):.3f} | {tan(rt,rho):.3f} | {rad(eq,rho):.3f} | {tan(eq,rho):.3f} |")

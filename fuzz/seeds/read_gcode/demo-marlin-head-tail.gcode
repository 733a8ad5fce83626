; pcpp 0.1.0
; scan file: demo-test-part.ply (6216475 bytes, sha256 dbe6d31e6e7355c626569e0fda9478dc16efd20a5bd223653c02c720dee787d9)
; path file: demo-test-part-lines.svg (659 bytes, sha256 59d5ff20ad48e19174edc3fc622ec0b592f1ab01fd86bf289a383636e8344544)
; nozzle: d 0.603 mm, do 0.908 mm
; process: tol 0.1 mm, speed 5 mm/s, dwell 0 s
; placement: offset (0, 80) mm, rotation 0 deg, scale 1
; planner: pcpp-guarded
; registration: lsq [1.000000 0.000000 0.000000 0.000000; 0.000000 1.000000 0.000000 0.000000; 0.000000 0.000000 1.000000 0.000000; 0.000000 0.000000 0.000000 1.000000]
; residuals: [] mm, rms 0.0000 mm
; path: 6 piece(s), 1362 points, 465.636 mm, height change 4.500 mm, max inclination 86.9 deg, min radius 0.145 mm, print time 93.1 s
; predicted quality: mean |e| 0.0671 mm, mean e- -0.0858 mm, mean e+ 0.0489 mm, contact 0.00%, flattening 15.57%, floating 4.11%
; warnings: 0
; profile: marlin
; print feed: F300 mm/min (5 mm/s)
; safe travel height: 13.603 mm
G21
G90
M107
G0 Z13.603 F3000
; subpath 0: 227 points
G0 X6.000 Y16.000 Z13.603 F3000
G1 X6.000 Y16.000 Z5.603 F3000
M106 S255
G1 X6.301 Y16.000 Z5.603 F300
G1 X6.602 Y16.000 Z5.603
G1 X6.903 Y16.000 Z5.603
G1 X7.204 Y16.000 Z5.603
G1 X7.504 Y16.000 Z5.603
G1 X7.805 Y16.000 Z5.603
G1 X8.106 Y16.000 Z5.603
G1 X8.407 Y16.000 Z5.603
G1 X8.708 Y16.000 Z5.603
G1 X9.009 Y16.000 Z5.603
G1 X9.310 Y16.000 Z5.603
G1 X9.611 Y16.000 Z5.603
G1 X9.912 Y16.000 Z5.603
G1 X10.212 Y16.000 Z5.603
G1 X10.513 Y16.000 Z5.603
G1 X10.814 Y16.000 Z5.603
G1 X11.115 Y16.000 Z5.603
G1 X73.699 Y66.000 Z5.603
G1 X74.000 Y66.000 Z5.603
M107
G0 Z13.603 F3000
M107
M84

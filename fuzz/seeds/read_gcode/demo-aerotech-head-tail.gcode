' pcpp 0.1.0
' scan file: demo-test-part.ply (6216475 bytes, sha256 dbe6d31e6e7355c626569e0fda9478dc16efd20a5bd223653c02c720dee787d9)
' path file: demo-test-part-lines.svg (659 bytes, sha256 59d5ff20ad48e19174edc3fc622ec0b592f1ab01fd86bf289a383636e8344544)
' nozzle: d 0.603 mm, do 0.908 mm
' process: tol 0.1 mm, speed 5 mm/s, dwell 0 s
' placement: offset (0, 80) mm, rotation 0 deg, scale 1
' planner: even
' registration: unregistered, taken as it is (the scan's frame is the printer's); G [1.000000 0.000000 0.000000 0.000000; 0.000000 1.000000 0.000000 0.000000; 0.000000 0.000000 1.000000 0.000000; 0.000000 0.000000 0.000000 1.000000]
' residuals: [] mm, rms 0.0000 mm
' path: 6 piece(s), 1362 points, 457.516 mm, height change 4.504 mm, max inclination 86.9 deg, min radius 0.145 mm, print time 91.5 s
' predicted quality: mean |e| 0.0136 mm, mean e- -0.0101 mm, mean e+ 0.0193 mm, contact 0.00%, flattening 1.03%, floating 1.76%
' safe motion: min clearance 0.101 mm (tol 0.1 mm) along all 1444 moves; 70 waypoint(s) added (+3.680 mm)
' warnings: 1
' profile: aerotech
' print feed: F5 mm/s (5 mm/s)
' safe travel height: 13.603 mm
G71
G76
G90
$DO[0].X = 0
G0 Z13.6030
' subpath 0: 247 points
G0 X6.4539 Y16.0000 Z13.6030
G1 X6.4539 Y16.0000 Z5.6030 F20
$DO[0].X = 1
G1 X6.6024 Y16.0000 Z5.6030 F5
G1 X6.9033 Y16.0000 Z5.6030
G1 X7.2042 Y16.0000 Z5.6030
G1 X7.5050 Y16.0000 Z5.6030
G1 X7.8059 Y16.0000 Z5.6030
G1 X8.1068 Y16.0000 Z5.6030
G1 X8.4077 Y16.0000 Z5.6030
G1 X8.7086 Y16.0000 Z5.6030
G1 X9.0095 Y16.0000 Z5.6030
G1 X9.3103 Y16.0000 Z5.6030
G1 X9.6112 Y16.0000 Z5.6030
G1 X9.9121 Y16.0000 Z5.6030
G1 X10.2130 Y16.0000 Z5.6030
G1 X10.5139 Y16.0000 Z5.6030
G1 X10.8148 Y16.0000 Z5.6030
G1 X74.0006 Y66.0000 Z5.6030
G1 X74.3015 Y66.0000 Z5.6030
$DO[0].X = 0
G0 Z13.6030
$DO[0].X = 0
M2

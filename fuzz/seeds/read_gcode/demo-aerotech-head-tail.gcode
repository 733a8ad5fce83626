' pcpp 0.1.0
' scan file: demo-test-part.ply (6216475 bytes, sha256 dbe6d31e6e7355c626569e0fda9478dc16efd20a5bd223653c02c720dee787d9)
' path file: demo-test-part-lines.svg (659 bytes, sha256 59d5ff20ad48e19174edc3fc622ec0b592f1ab01fd86bf289a383636e8344544)
' nozzle: d 0.603 mm, do 0.908 mm
' process: tol 0.1 mm, speed 5 mm/s, dwell 0 s
' placement: offset (0, 80) mm, rotation 0 deg, scale 1
' planner: pcpp-guarded
' registration: lsq [1.000000 0.000000 0.000000 0.000000; 0.000000 1.000000 0.000000 0.000000; 0.000000 0.000000 1.000000 0.000000; 0.000000 0.000000 0.000000 1.000000]
' residuals: [] mm, rms 0.0000 mm
' path: 6 piece(s), 1362 points, 465.636 mm, height change 4.500 mm, max inclination 86.9 deg, min radius 0.145 mm, print time 93.1 s
' predicted quality: mean |e| 0.0671 mm, mean e- -0.0858 mm, mean e+ 0.0489 mm, contact 0.00%, flattening 15.57%, floating 4.11%
' warnings: 0
' profile: aerotech
' print feed: F5 mm/s (5 mm/s)
' safe travel height: 13.603 mm
G71
G76
G90
$DO[0].X = 0
G0 Z13.6030
' subpath 0: 227 points
G0 X6.0000 Y16.0000 Z13.6030
G1 X6.0000 Y16.0000 Z5.6030 F20
$DO[0].X = 1
G1 X6.3009 Y16.0000 Z5.6030 F5
G1 X6.6018 Y16.0000 Z5.6030
G1 X6.9027 Y16.0000 Z5.6030
G1 X7.2035 Y16.0000 Z5.6030
G1 X7.5044 Y16.0000 Z5.6030
G1 X7.8053 Y16.0000 Z5.6030
G1 X8.1062 Y16.0000 Z5.6030
G1 X8.4071 Y16.0000 Z5.6030
G1 X8.7080 Y16.0000 Z5.6030
G1 X9.0088 Y16.0000 Z5.6030
G1 X9.3097 Y16.0000 Z5.6030
G1 X9.6106 Y16.0000 Z5.6030
G1 X9.9115 Y16.0000 Z5.6030
G1 X10.2124 Y16.0000 Z5.6030
G1 X10.5133 Y16.0000 Z5.6030
G1 X10.8142 Y16.0000 Z5.6030
G1 X73.6991 Y66.0000 Z5.6030
G1 X74.0000 Y66.0000 Z5.6030
$DO[0].X = 0
G0 Z13.6030
$DO[0].X = 0
M2

%
; RepRap/Marlin
N1 G21*27
N2 G90 G0 X0 Y0 Z5 F3000
G1X1Y2Z.5E0.1 (inline) ; comment
M201 X1000 Y1000
M117 Printing (50%
G91
G1 X1 Y-1.5 Z+0.25
G90
G20
G1 X0.1 Y0.2
G21
G92 X0 Y0 Z0
G92
G92.2
G92.3
G92.1
G28 X Y
G1 X1 Y1 Z1
G53 G0 Z0
G29
$H
$J=G91 X1
/G1 X2
G10
G11
G4 P100
G17 G40 G49 G61 G64 G80 G94
G1 Z2
X3 Y3
M291 P"a ""quoted"" string" S1
' aerotech
G71 G76
$DO[0].X = 1
DWELL 0.5
HOME X Y Z
G70
G1 X1 // aerotech comment
%

%
(designopt example: two pockets in one aluminium plate, 3-flute 10 mm end mill)
(program zero = workpiece frame W: top face of the block, units mm)
N10 G21 G90 G17 G94
N20 M3 S12000
(--- region 1: rounded rectangular pocket, 40 x 24 mm, corner radius 6, 1 mm deep ---)
N30 G0 X-34 Y-6 Z5
N40 G1 Z-1 F300
N50 G1 Y6 F900
N60 G2 X-28 Y12 I6 J0
N70 G1 X-8
N80 G2 X-2 Y6 R6 (a corner by radius)
N90 G1 Y-6
N100 G2 X-8 Y-12 I-6 J0
N110 G1 X-28
N120 G2 X-34 Y-6 I0 J6
N130 G0 Z5
(--- rapid to region 2 ---)
N140 G0 X22 Y0
(--- region 2: circular pocket, a full circle of radius 12, a step in, a circle of radius 6 ---)
N150 G1 Z-1 F300
N160 G3 X22 Y0 I-12 J0 F900
N170 G1 X16
N175 G3 X16 Y0 I-6 J0
N180 G0 Z5
N190 M5
N200 M30
%

; worksheet 07: long moves, then short zigzag steps; plain G-code every firmware reads
G21
G90
G0 X0 Y0 F6000
G1 X100 F6000
G1 Y2
G1 X0
G1 Y4
G1 X100
G1 X100.5 Y4.5
G1 X101 Y4
G1 X101.5 Y4.5
G1 X102 Y4
G1 X102.5 Y4.5
G1 X103 Y4
G1 Y30
G1 X0

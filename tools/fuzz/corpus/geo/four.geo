LSMGeometry 1.2
BoundingBox 0 0 0 10 10 10
PeriodicBoundaries 0 0 0
Dimension 3D
BeginParticles
Simple
4
1.0 1.0 1.0 0.5 10 1
2.0 1.0 1.0 0.5 11 1
3.0 1.0 1.0 0.5 12 1
4.0 1.0 1.0 0.5 13 2
EndParticles
BeginConnect
3
10 11 0
11 12 0
12 13 1
EndConnect

#!/usr/bin/python3
# The exact critical step of the radius-ratio packing of tests/solver/test_extremes.cpp (mixed_packing): a
# dense eigen-solve of M^-1 K for its bonds and touching contacts (K = 1000, density 1), the reference
# RadiusRatio.CriticalStepSeesTheSmallestParticle holds. Usage: /usr/bin/python3 tools/studies/ratio_packing_omega.py RATIO [0 = no contacts]
import sys
import numpy as np
ratio=float(sys.argv[1]); contacts=int(sys.argv[2]) if len(sys.argv)>2 else 1
R=1.0; s=1.98; r=R/ratio; q=1.98*r
pos=[];rad=[]
for i in range(2):
  for j in range(2):
    for k in range(2): pos.append((i*s,j*s,k*s)); rad.append(R)
bonds=[]
for a in range(8):
  for b in range(a+1,8):
    if np.linalg.norm(np.subtract(pos[a],pos[b]))<1.01*s: bonds.append((a,b))
top=s+R; m=8; first=8
sid=lambda i,j,k: first+(k*m+j)*m+i
for k in range(2):
  for j in range(m):
    for i in range(m): pos.append(((i-(m-1)/2)*q,(j-(m-1)/2)*q,top+0.9*r+k*q)); rad.append(r)
pos=np.array(pos)
for a in range(first,len(pos)):
  for b in range(a+1,len(pos)):
    if np.linalg.norm(pos[a]-pos[b])<1.5*q: bonds.append((a,b)); rad=np.array(rad); n=len(pos)
bs=set(bonds)
springs=list(bonds)
if contacts:
  for a in range(n):
    for b in range(a+1,n):
      if (a,b) in bs: continue
      if np.linalg.norm(pos[a]-pos[b])<rad[a]+rad[b]: springs.append((a,b))
K=np.zeros((3*n,3*n))
for a,b in springs:
  d=pos[b]-pos[a]; nn=d/np.linalg.norm(d); B=1000*np.outer(nn,nn)
  for (x,y,sg) in [(a,a,1),(b,b,1),(a,b,-1),(b,a,-1)]:
    K[3*x:3*x+3,3*y:3*y+3]+=sg*B
M=np.repeat(4/3*np.pi*rad**3,3)
A=K/np.sqrt(np.outer(M,M))
w=np.linalg.eigvalsh(A)
print("springs",len(springs),"omega_max^2",w[-1],"dt_c",2/np.sqrt(w[-1]), "next", 2/np.sqrt(w[-2]), 2/np.sqrt(w[-5]))

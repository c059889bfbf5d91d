#!/usr/bin/env python3
# An independent check of test/scenes/symmetric_clearance_pendulum.urdf without
# friction, written apart from the engine: the rod as a smooth constrained system,
# both rings held on the pin's wall (bilateral constraints |c_xy| = c_r with
# Baumgarte stabilisation), integrated by RK4 on the rotation group. It runs the
# in-plane motion and a copy kicked by 1e-9 rad/s about the rod's in-plane axes,
# and prints their attitude difference every ms. It grows by ~1e7 in 30 ms: the
# in-plane motion on two rings is unstable in the model itself.
# Usage: bench/symmetric_pendulum_smooth.py [I_axis kg m^2 (1e-7)] [T s (0.03)] [h s (2e-6)]
import numpy as np, sys
m=0.1; Ib=np.diag([8.333333333333333e-5, float(sys.argv[1]) if len(sys.argv)>1 else 1e-7, 8.333333333333333e-5])
g=np.array([0,-9.81,0]); R=5.0e-3; r=4.95e-3; cr=R-r; L=6e-3
th0=-1.0471975511965976
def rotz(a): c,s=np.cos(a),np.sin(a); return np.array([[c,-s,0],[s,c,0],[0,0,1.]])
def expso3(w):
    a=np.linalg.norm(w)
    if a<1e-300: return np.eye(3)
    k=w/a; K=np.array([[0,-k[2],k[1]],[k[2],0,-k[0]],[-k[1],k[0],0]])
    return np.eye(3)+np.sin(a)*K+(1-np.cos(a))*K@K
# body frame: pin (bore centre) at body (0, 0.05, 0) from the CoM (rod along -y from pin)
cb=[np.array([0,0.05, L/2]), np.array([0,0.05,-L/2])]
def G_of(x,Q):
    G=np.zeros((2,6)); gg=np.zeros(2)
    for i in range(2):
        c=x+Q@cb[i]; d=c[:2]; dn=np.linalg.norm(d); u=np.array([d[0]/dn,d[1]/dn,0.])
        ri=c-x
        G[i,:3]=u; G[i,3:]=np.cross(ri,u)   # d/dt |c_xy| = u.(v + w x ri)
        gg[i]=dn-cr
    return G,gg
def acc(x,Q,v,w,alpha=2e3):
    Iw=Q@Ib@Q.T; Iwi=np.linalg.inv(Iw)
    Minv=np.zeros((6,6)); Minv[:3,:3]=np.eye(3)/m; Minv[3:,3:]=Iwi
    F=np.concatenate([m*g, -np.cross(w,Iw@w)])
    G,gg=G_of(x,Q); V=np.concatenate([v,w])
    eps=1e-7
    G2,_=G_of(x+eps*v, expso3(eps*w)@Q)
    Gdv=(G2-G)@V/eps
    rhs=-Gdv-2*alpha*(G@V)-alpha**2*gg - G@Minv@F
    lam=np.linalg.solve(G@Minv@G.T, rhs)
    a=Minv@(F+G.T@lam)
    return a[:3],a[3:],lam
def run(kick,T,h):
    # start: rod at th0, bore centre displaced by cr along the rod (towards the CoM)
    Q=rotz(th0); u=Q@np.array([0,-1.,0])
    x=cr*u - Q@np.array([0,0.05,0])   # pin centre (bore centre) at cr*u
    v=np.zeros(3); w=Q@np.array([kick,kick,0.])
    out=[]; t=0; nxt=0
    while t<T-1e-12:
        def f(s):
            x_,Q_,v_,w_=s; a,al,lam=acc(x_,Q_,v_,w_); return (v_,w_,a,al)
        def add(s,k,c):
            x_,Q_,v_,w_=s; return (x_+c*k[0], expso3(c*k[1])@Q_, v_+c*k[2], w_+c*k[3])
        s=(x,Q,v,w)
        k1=f(s); k2=f(add(s,k1,h/2)); k3=f(add(s,k2,h/2)); k4=f(add(s,k3,h))
        x=x+h/6*(k1[0]+2*k2[0]+2*k3[0]+k4[0]); v=v+h/6*(k1[2]+2*k2[2]+2*k3[2]+k4[2]); w=w+h/6*(k1[3]+2*k2[3]+2*k3[3]+k4[3])
        Q=expso3(h/6*(k1[1]+2*k2[1]+2*k3[1]+k4[1]))@Q
        t+=h
        if t>=nxt-1e-12:
            z=Q@np.array([0,0,1.]); _,_,lam=acc(x,Q,v,w)
            out.append((t,z[0],z[1],lam[0],lam[1],np.arctan2(Q[1,0],Q[0,0]))); nxt+=1e-3
    return out
T=float(sys.argv[2]) if len(sys.argv)>2 else 0.03; h=float(sys.argv[3]) if len(sys.argv)>3 else 2e-6
a=run(0,T,h); b=run(1e-9,T,h)
for A,B in zip(a,b):
    print("t=%.3f  angle=%+.4f  tilt diff=%.3e  lam=(%.3f,%.3f)"%(A[0],A[5],np.hypot(B[1]-A[1],B[2]-A[2]),A[3],A[4]))

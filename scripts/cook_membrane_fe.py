# Independent check of tests/cases/tapered_plate.toml: Q1 finite elements with B̄ (mean dilatation),
# plane strain, E = 1 MPa, ν = 0.499, the Cook membrane (0,0)-(48,44)-(48,60)-(0,44) clamped at x = 0
# and sheared by q = 1 Pa on x = 48; prints the tip (48, 60) vertical displacement for n × n meshes.
# Dense numpy only (no scipy). Quoted in docs/verification.md.
import numpy as np
E,nu,q=1e6,0.499,1.0
lam=E*nu/((1+nu)*(1-2*nu)); mu=E/(2*(1+nu)); K=lam+2*mu/3
def solve(n):
    xi=np.linspace(0,1,n+1)
    X=np.zeros(((n+1)**2,2))
    for j in range(n+1):
        for i in range(n+1):
            s,t=xi[i],xi[j]
            x=48*s; ylo=44*s; yhi=44+16*s
            X[j*(n+1)+i]=[x, ylo+t*(yhi-ylo)]
    nd=len(X); Kg=np.zeros((2*nd,2*nd)); f=np.zeros(2*nd)
    g=np.array([-1,1])/np.sqrt(3)
    Ddev=mu*np.array([[4/3,-2/3,0],[-2/3,4/3,0],[0,0,1]])
    m=np.array([1,1,0])
    for j in range(n):
        for i in range(n):
            nodes=[j*(n+1)+i, j*(n+1)+i+1, (j+1)*(n+1)+i+1, (j+1)*(n+1)+i]
            xe=X[nodes]
            ke=np.zeros((8,8)); bv=np.zeros(8); vol=0
            for a in g:
                for b in g:
                    dN=0.25*np.array([[-(1-b),(1-b),(1+b),-(1+b)],[-(1-a),-(1+a),(1+a),(1-a)]])
                    J=dN@xe; dx=np.linalg.solve(J,dN); w=np.linalg.det(J)
                    B=np.zeros((3,8)); B[0,0::2]=dx[0]; B[1,1::2]=dx[1]; B[2,0::2]=dx[1]; B[2,1::2]=dx[0]
                    ke+=B.T@Ddev@B*w; bv+=(m@B)*w; vol+=w
            ke+=K*np.outer(bv,bv)/vol
            dofs=np.array([[2*k,2*k+1] for k in nodes]).ravel()
            Kg[np.ix_(dofs,dofs)]+=ke
    # traction on right edge i=n
    for j in range(n):
        a,b=j*(n+1)+n,(j+1)*(n+1)+n
        L=np.linalg.norm(X[b]-X[a]); f[2*a+1]+=q*L/2; f[2*b+1]+=q*L/2
    fixed=[]
    for j in range(n+1):
        k=j*(n+1); fixed+= [2*k,2*k+1]
    free=np.setdiff1d(np.arange(2*nd),fixed)
    u=np.zeros(2*nd); u[free]=np.linalg.solve(Kg[np.ix_(free,free)],f[free])
    tip=(n)*(n+1)+n
    return u[2*tip+1]
for n in [8,16,32,48]:
    print(n, solve(n))

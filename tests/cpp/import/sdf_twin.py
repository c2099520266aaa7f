# Prints the URDF twin of tests/cpp/import/sdf_loader_test.cpp kSdfArm: each SDF frame composed by hand
# (4x4 transforms, rpy as URDF and SDF define it: R = Rz(yaw) Ry(pitch) Rx(roll)), then expressed as URDF origins.
import math
def rpy_mat(r,p,y):
    cr,sr,cp,sp,cy,sy=math.cos(r),math.sin(r),math.cos(p),math.sin(p),math.cos(y),math.sin(y)
    return [[cy*cp, cy*sp*sr-sy*cr, cy*sp*cr+sy*sr],[sy*cp, sy*sp*sr+cy*cr, sy*sp*cr-cy*sr],[-sp, cp*sr, cp*cr]]
def T(x,y,z,r,p,yw):
    R=rpy_mat(r,p,yw); return [[R[0][0],R[0][1],R[0][2],x],[R[1][0],R[1][1],R[1][2],y],[R[2][0],R[2][1],R[2][2],z],[0,0,0,1]]
def mul(A,B): return [[sum(A[i][k]*B[k][j] for k in range(4)) for j in range(4)] for i in range(4)]
def inv(A):
    R=[[A[j][i] for j in range(3)] for i in range(3)]; t=[-sum(R[i][k]*A[k][3] for k in range(3)) for i in range(3)]
    return [R[0]+[t[0]],R[1]+[t[1]],R[2]+[t[2]],[0,0,0,1]]
def rpy(A):
    p=math.asin(-A[2][0]); r=math.atan2(A[2][1],A[2][2]); y=math.atan2(A[1][0],A[0][0]); return r,p,y
def origin(A):
    r,p,y=rpy(A); return '<origin xyz="%.17g %.17g %.17g" rpy="%.17g %.17g %.17g"/>'%(A[0][3],A[1][3],A[2][3],r,p,y)
hp=1.5707963267948966
mount=T(0,0,0.1,0,0,0.3)
base=mul(mount,T(0.05,0,0,0,0,0))
J1=mul(base,T(0,0,0.5,0,0,hp)); upper=J1
lower=mul(upper,T(0.3,0,0,0,0.2,0))
J2=mul(lower,T(0.01,0.02,0,0.1,0,0))
tool=mul(lower,T(0,0,0.1,0,0,0))
slider=mul(lower,T(0,-0.05,0,0,0,0))
print('shoulder', origin(mul(inv(base),J1)))
print('elbow', origin(mul(inv(upper),J2)))
print('elbow__frame', origin(mul(inv(J2),lower)))
print('tool', origin(mul(inv(lower),tool)))
print('slide', origin(mul(inv(lower),slider)))
# slide axis (0,1,0) in model frame -> slider frame
a=[slider[k][1] for k in range(3)]  # R^T * (0,1,0) = row? R^T e_y = column? R^T[i][1]=R[1][i]
a=[slider[1][i] for i in range(3)]
print('slide axis %.17g %.17g %.17g'%tuple(a))
# collision on lower relative_to elbow: pose (0,0,0.05, 0,0,0)
print('lower collision', origin(mul(mul(inv(lower),J2),T(0,0,0.05,0,0,0))))

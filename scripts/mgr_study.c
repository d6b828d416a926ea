/* hypre's multigrid reduction (MGR) against porompm's Schur field split on a tangent porompm wrote.
 *
 * Loads a u–p–U tangent (5 interlaced dofs per node: ux, uy, p, Ux, Uy) and its right-hand side in
 * PETSc's binary format (`-ksp_view_mat binary:A.bin -ksp_view_rhs binary:b.bin`), solves it with
 * right-preconditioned FGMRES to a relative residual of 1e-8 and prints the Krylov iterations, the
 * set-up and solve times and the residual of each field over the norm of the whole right-hand side.
 * The preconditioner is either the options database's (`-use_mgr 0` and, for instance, a Schur
 * field split by component lists) or, by default, hypre MGR through a shell preconditioner on
 * MatHYPREGetParCSR (PETSc 3.18's PCHYPRE offers no MGR):
 *   -mgr_scheme 1: one reduction, C = {p}, F = {ux, uy, Ux, Uy} relaxed by one BoomerAMG V-cycle
 *                  (4 functions); the coarse pressure system solved by one BoomerAMG V-cycle;
 *   -mgr_scheme 2: two reductions, first F = {Ux, Uy} (Jacobi), then F = {ux, uy} (BoomerAMG);
 *   -mgr_cg K (hypre's coarse-grid method, 0 Galerkin), -mgr_interp K, -mgr_restrict K
 *   (interpolation and restriction, defaults 2 = Jacobi and 0 = injection: the Galerkin coarse
 *   operator is then A_pp − A_pF diag(A_FF)⁻¹ A_Fp, PETSc's selfp), -mgr_gsmooth N (global
 *   smoothing sweeps).
 * Used by scripts/mgr_study.sh (`make study-mgr`); the table is in docs/solvers.md. */
#include <petscksp.h>
#include <petscmathypre.h>
#include <HYPRE.h>
#include <HYPRE_IJ_mv.h>
#include <HYPRE_parcsr_ls.h>

#define BS 5

typedef struct {
  Mat hypre_mat;
  HYPRE_Solver mgr, coarse;
  HYPRE_IJVector b, x;
  HYPRE_BigInt *rows;
  PetscInt n;
} Ctx;

static PetscInt scheme = 1, cg = 0, interp = 2, restrict_type = 0, gsmooth = 0;

static PetscErrorCode mgr_setup(PC pc) {
  Ctx *c;
  Mat a, p;
  hypre_ParCSRMatrix *par;
  PetscInt rs, re, i;
  HYPRE_Int *marker, nlev, ncp[2], *cidx[2], level0[3] = {0, 1, 2}, pressure[1] = {2};
  HYPRE_Int frelax[2], functions[2], cgm[2], it[2], rt[2];
  HYPRE_ParVector pb, px;
  PetscFunctionBeginUser;
  PetscCall(PCShellGetContext(pc, &c));
  PetscCall(PCGetOperators(pc, &a, &p));
  PetscCall(MatConvert(p, MATHYPRE, MAT_INITIAL_MATRIX, &c->hypre_mat));
  PetscCall(MatHYPREGetParCSR(c->hypre_mat, &par));
  PetscCall(MatGetOwnershipRange(p, &rs, &re));
  c->n = re - rs;
  PetscCall(PetscMalloc1(c->n, &marker));
  PetscCall(PetscMalloc1(c->n, &c->rows));
  for (i = 0; i < c->n; i++) {
    marker[i] = (HYPRE_Int)((rs + i) % BS);
    c->rows[i] = rs + i;
  }
  if (scheme == 1) {
    nlev = 1; ncp[0] = 1; cidx[0] = pressure; frelax[0] = 2; functions[0] = 4;
  } else {
    nlev = 2; ncp[0] = 3; ncp[1] = 1; cidx[0] = level0; cidx[1] = pressure;
    frelax[0] = 0; frelax[1] = 2; functions[0] = 2; functions[1] = 2;
  }
  for (i = 0; i < nlev; i++) { cgm[i] = (HYPRE_Int)cg; it[i] = (HYPRE_Int)interp; rt[i] = (HYPRE_Int)restrict_type; }
  HYPRE_MGRCreate(&c->mgr);
  HYPRE_MGRSetCpointsByPointMarkerArray(c->mgr, BS, nlev, ncp, cidx, marker);
  HYPRE_MGRSetNonCpointsToFpoints(c->mgr, 1);
  HYPRE_MGRSetMaxCoarseLevels(c->mgr, nlev);
  HYPRE_MGRSetLevelFRelaxType(c->mgr, frelax);
  HYPRE_MGRSetLevelFRelaxNumFunctions(c->mgr, functions);
  HYPRE_MGRSetCoarseGridMethod(c->mgr, cgm);
  HYPRE_MGRSetLevelInterpType(c->mgr, it);
  HYPRE_MGRSetLevelRestrictType(c->mgr, rt);
  HYPRE_MGRSetNumRelaxSweeps(c->mgr, 1);
  HYPRE_MGRSetMaxGlobalSmoothIters(c->mgr, (HYPRE_Int)gsmooth);
  HYPRE_MGRSetMaxIter(c->mgr, 1);
  HYPRE_MGRSetTol(c->mgr, 0.0);
  HYPRE_BoomerAMGCreate(&c->coarse);
  HYPRE_BoomerAMGSetMaxIter(c->coarse, 1);
  HYPRE_BoomerAMGSetTol(c->coarse, 0.0);
  HYPRE_BoomerAMGSetRelaxType(c->coarse, 6);
  HYPRE_MGRSetCoarseSolver(c->mgr, HYPRE_BoomerAMGSolve, HYPRE_BoomerAMGSetup, c->coarse);
  for (i = 0; i < 2; i++) {
    HYPRE_IJVector *v = i ? &c->x : &c->b;
    HYPRE_IJVectorCreate(PetscObjectComm((PetscObject)p), rs, re - 1, v);
    HYPRE_IJVectorSetObjectType(*v, HYPRE_PARCSR);
    HYPRE_IJVectorInitialize(*v);
    HYPRE_IJVectorAssemble(*v);
  }
  HYPRE_IJVectorGetObject(c->b, (void **)&pb);
  HYPRE_IJVectorGetObject(c->x, (void **)&px);
  PetscCheck(HYPRE_MGRSetup(c->mgr, (HYPRE_ParCSRMatrix)par, pb, px) == 0, PETSC_COMM_SELF, PETSC_ERR_LIB, "HYPRE_MGRSetup failed");
  PetscCall(PetscFree(marker));
  PetscFunctionReturn(0);
}

static PetscErrorCode mgr_apply(PC pc, Vec b, Vec x) {
  Ctx *c;
  hypre_ParCSRMatrix *par;
  const PetscScalar *ba;
  PetscScalar *xa;
  HYPRE_ParVector pb, px;
  PetscFunctionBeginUser;
  PetscCall(PCShellGetContext(pc, &c));
  PetscCall(MatHYPREGetParCSR(c->hypre_mat, &par));
  PetscCall(VecGetArrayRead(b, &ba));
  HYPRE_IJVectorSetValues(c->b, (HYPRE_Int)c->n, c->rows, ba);
  PetscCall(VecRestoreArrayRead(b, &ba));
  PetscCall(VecSet(x, 0.0));
  PetscCall(VecGetArray(x, &xa));
  HYPRE_IJVectorSetValues(c->x, (HYPRE_Int)c->n, c->rows, xa);
  HYPRE_IJVectorGetObject(c->b, (void **)&pb);
  HYPRE_IJVectorGetObject(c->x, (void **)&px);
  HYPRE_MGRSolve(c->mgr, (HYPRE_ParCSRMatrix)par, pb, px);
  HYPRE_IJVectorGetValues(c->x, (HYPRE_Int)c->n, c->rows, xa);
  PetscCall(VecRestoreArray(x, &xa));
  PetscFunctionReturn(0);
}

int main(int argc, char **argv) {
  Mat a;
  Vec b, x, r;
  KSP ksp;
  PC pc;
  PetscViewer v;
  char fa[PETSC_MAX_PATH_LEN], fb[PETSC_MAX_PATH_LEN];
  PetscInt its, n, rs, re, i, use_mgr = 1;
  PetscLogDouble t0, t1, t2;
  KSPConvergedReason reason;
  Ctx ctx = {0};
  PetscReal rf[3] = {0, 0, 0}, bf[3] = {0, 0, 0};
  const PetscScalar *ra, *bb;
  PetscCall(PetscInitialize(&argc, &argv, NULL, NULL));
  PetscCall(PetscOptionsGetString(NULL, NULL, "-A", fa, sizeof(fa), NULL));
  PetscCall(PetscOptionsGetString(NULL, NULL, "-b", fb, sizeof(fb), NULL));
  PetscCall(PetscOptionsGetInt(NULL, NULL, "-use_mgr", &use_mgr, NULL));
  PetscCall(PetscOptionsGetInt(NULL, NULL, "-mgr_scheme", &scheme, NULL));
  PetscCall(PetscOptionsGetInt(NULL, NULL, "-mgr_cg", &cg, NULL));
  PetscCall(PetscOptionsGetInt(NULL, NULL, "-mgr_interp", &interp, NULL));
  PetscCall(PetscOptionsGetInt(NULL, NULL, "-mgr_restrict", &restrict_type, NULL));
  PetscCall(PetscOptionsGetInt(NULL, NULL, "-mgr_gsmooth", &gsmooth, NULL));
  PetscCall(PetscViewerBinaryOpen(PETSC_COMM_WORLD, fa, FILE_MODE_READ, &v));
  PetscCall(MatCreate(PETSC_COMM_WORLD, &a));
  PetscCall(MatSetBlockSize(a, BS));
  PetscCall(MatSetFromOptions(a));
  PetscCall(MatLoad(a, v));
  PetscCall(PetscViewerDestroy(&v));
  PetscCall(PetscViewerBinaryOpen(PETSC_COMM_WORLD, fb, FILE_MODE_READ, &v));
  PetscCall(VecCreate(PETSC_COMM_WORLD, &b));
  PetscCall(VecLoad(b, v));
  PetscCall(PetscViewerDestroy(&v));
  PetscCall(MatGetSize(a, &n, NULL));
  PetscCall(MatGetOwnershipRange(a, &rs, &re));
  PetscCall(VecDuplicate(b, &x));
  PetscCall(VecDuplicate(b, &r));
  PetscCall(KSPCreate(PETSC_COMM_WORLD, &ksp));
  PetscCall(KSPSetOperators(ksp, a, a));
  PetscCall(KSPSetType(ksp, KSPFGMRES));
  PetscCall(KSPSetTolerances(ksp, 1e-8, PETSC_DEFAULT, PETSC_DEFAULT, 500));
  PetscCall(KSPGetPC(ksp, &pc));
  if (use_mgr) {
    PetscCall(PCSetType(pc, PCSHELL));
    PetscCall(PCShellSetContext(pc, &ctx));
    PetscCall(PCShellSetSetUp(pc, mgr_setup));
    PetscCall(PCShellSetApply(pc, mgr_apply));
  }
  PetscCall(KSPSetFromOptions(ksp));
  PetscCall(PetscTime(&t0));
  PetscCall(KSPSetUp(ksp));
  PetscCall(PetscTime(&t1));
  PetscCall(VecSet(x, 0));
  PetscCall(KSPSolve(ksp, b, x));
  PetscCall(PetscTime(&t2));
  PetscCall(KSPGetIterationNumber(ksp, &its));
  PetscCall(KSPGetConvergedReason(ksp, &reason));
  PetscCall(MatMult(a, x, r));
  PetscCall(VecAYPX(r, -1.0, b));
  PetscCall(VecGetArrayRead(r, &ra));
  PetscCall(VecGetArrayRead(b, &bb));
  for (i = 0; i < re - rs; i++) {
    PetscInt comp = (rs + i) % BS, f = comp < 2 ? 0 : (comp == 2 ? 1 : 2);
    rf[f] += PetscRealPart(ra[i] * ra[i]);
    bf[f] += PetscRealPart(bb[i] * bb[i]);
  }
  PetscCall(VecRestoreArrayRead(r, &ra));
  PetscCall(VecRestoreArrayRead(b, &bb));
  /* Each field's residual over the whole right-hand side's norm (the pressure's part of b may be
     zero; porompm's scaled unknowns make the fields comparable). */
  bf[0] += bf[1] + bf[2];
  PetscCall(PetscPrintf(PETSC_COMM_WORLD, "rows %d iterations %d %s set-up %.2f s solve %.2f s residual/|b| u %.1e p %.1e U %.1e\n", (int)n,
                        (int)its, KSPConvergedReasons[reason], t1 - t0, t2 - t1, sqrt(rf[0] / bf[0]), sqrt(rf[1] / bf[0]), sqrt(rf[2] / bf[0])));
  PetscCall(KSPDestroy(&ksp));
  if (ctx.mgr) {
    HYPRE_MGRDestroy(ctx.mgr);
    HYPRE_BoomerAMGDestroy(ctx.coarse);
    HYPRE_IJVectorDestroy(ctx.b);
    HYPRE_IJVectorDestroy(ctx.x);
    PetscCall(PetscFree(ctx.rows));
    PetscCall(MatDestroy(&ctx.hypre_mat));
  }
  PetscCall(MatDestroy(&a));
  PetscCall(VecDestroy(&b));
  PetscCall(VecDestroy(&x));
  PetscCall(VecDestroy(&r));
  PetscCall(PetscFinalize());
  return 0;
}

/* MA27's four calls passed on to another library that has them (KKT_RECORD_LIB: the LDLᵀ of
 * designopt/solve/backends/ldl), each matrix IPOPT factorises written to KKT_RECORD_DIR first: kNNNNN.bin holds n, nz
 * (int32), the triplets' rows and columns (int32, 1-based) and values (float64), as ma27bd is given them.
 * benchmarks/kkt_ldl.py builds it, hands it to IPOPT as its `hsllib` and reads the files back. */
#include <dlfcn.h>
#include <stdio.h>
#include <stdlib.h>

typedef void (*id_t_)(int *, double *);
typedef void (*ad_t_)(int *, int *, const int *, const int *, int *, int *, int *, int *, int *, int *, int *,
                      double *, int *, double *);
typedef void (*bd_t_)(int *, int *, const int *, const int *, double *, int *, int *, int *, int *, int *, int *,
                      int *, int *, double *, int *);
typedef void (*cd_t_)(int *, double *, int *, int *, int *, double *, int *, double *, int *, int *, int *, int *);

static void *lib;
static int count;

static void *call(const char *name) {
    if (!lib) {
        lib = dlopen(getenv("KKT_RECORD_LIB"), RTLD_NOW | RTLD_LOCAL);
        if (!lib) { fprintf(stderr, "kkt_record: %s\n", dlerror()); abort(); }
    }
    void *f = dlsym(lib, name);
    if (!f) { fprintf(stderr, "kkt_record: no %s\n", name); abort(); }
    return f;
}

void ma27id_(int *ICNTL, double *CNTL) { ((id_t_)call("ma27id_"))(ICNTL, CNTL); }

void ma27ad_(int *N, int *NZ, const int *IRN, const int *ICN, int *IW, int *LIW, int *IKEEP, int *IW1, int *NSTEPS,
             int *IFLAG, int *ICNTL, double *CNTL, int *INFO, double *OPS) {
    ((ad_t_)call("ma27ad_"))(N, NZ, IRN, ICN, IW, LIW, IKEEP, IW1, NSTEPS, IFLAG, ICNTL, CNTL, INFO, OPS);
}

void ma27bd_(int *N, int *NZ, const int *IRN, const int *ICN, double *A, int *LA, int *IW, int *LIW, int *IKEEP,
             int *NSTEPS, int *MAXFRT, int *IW1, int *ICNTL, double *CNTL, int *INFO) {
    const char *dir = getenv("KKT_RECORD_DIR");
    if (dir) {
        char path[4096];
        snprintf(path, sizeof path, "%s/k%05d.bin", dir, count++);
        FILE *f = fopen(path, "wb");
        if (f) {
            fwrite(N, sizeof(int), 1, f);
            fwrite(NZ, sizeof(int), 1, f);
            fwrite(IRN, sizeof(int), (size_t)*NZ, f);
            fwrite(ICN, sizeof(int), (size_t)*NZ, f);
            fwrite(A, sizeof(double), (size_t)*NZ, f);
            fclose(f);
        }
    }
    ((bd_t_)call("ma27bd_"))(N, NZ, IRN, ICN, A, LA, IW, LIW, IKEEP, NSTEPS, MAXFRT, IW1, ICNTL, CNTL, INFO);
}

void ma27cd_(int *N, double *A, int *LA, int *IW, int *LIW, double *W, int *MAXFRT, double *RHS, int *IW1,
             int *NSTEPS, int *ICNTL, int *INFO) {
    ((cd_t_)call("ma27cd_"))(N, A, LA, IW, LIW, W, MAXFRT, RHS, IW1, NSTEPS, ICNTL, INFO);
}

/* without the trailing underscore, as IPOPT's loader may look them up */
void ma27id(int *ICNTL, double *CNTL) { ma27id_(ICNTL, CNTL); }
void ma27ad(int *N, int *NZ, const int *IRN, const int *ICN, int *IW, int *LIW, int *IKEEP, int *IW1, int *NSTEPS,
            int *IFLAG, int *ICNTL, double *CNTL, int *INFO, double *OPS) {
    ma27ad_(N, NZ, IRN, ICN, IW, LIW, IKEEP, IW1, NSTEPS, IFLAG, ICNTL, CNTL, INFO, OPS);
}
void ma27bd(int *N, int *NZ, const int *IRN, const int *ICN, double *A, int *LA, int *IW, int *LIW, int *IKEEP,
            int *NSTEPS, int *MAXFRT, int *IW1, int *ICNTL, double *CNTL, int *INFO) {
    ma27bd_(N, NZ, IRN, ICN, A, LA, IW, LIW, IKEEP, NSTEPS, MAXFRT, IW1, ICNTL, CNTL, INFO);
}
void ma27cd(int *N, double *A, int *LA, int *IW, int *LIW, double *W, int *MAXFRT, double *RHS, int *IW1,
            int *NSTEPS, int *ICNTL, int *INFO) {
    ma27cd_(N, A, LA, IW, LIW, W, MAXFRT, RHS, IW1, NSTEPS, ICNTL, INFO);
}

/* MA27's four calls -- ma27id, ma27ad, ma27bd, ma27cd, as IPOPT loads them at run time from the library its
 * `hsllib` option names -- over an AMD ordering (SuiteSparse AMD, amd/) and QDLDL's sparse LDL^T (qdldl.c).
 *
 * This is not MA27: there is no numerical pivoting. A pivot that is exactly zero is reported as a singular matrix
 * (IFLAG -5), which IPOPT answers by regularising the constraint block (delta_c > 0, after which the KKT matrix
 * is quasi-definite whenever its Hessian block is positive definite on the null space); the inertia is the signs
 * of D (Sylvester's law), which IPOPT checks and corrects as with any solver that reports it.
 *
 * Where MA27 keeps things, this keeps them too, so that nothing is allocated between calls and nothing leaks when
 * IPOPT drops a solver: the ordering in IKEEP (3n ints, from ma27ad on), the factors in A (doubles) and IW (ints),
 * whose sizes ma27ad asks for through INFO(5) and INFO(6). Layouts:
 *   IKEEP: P[n] (new -> old), Pinv[n] (old -> new), then (n >= RECORD) nnzA, nnzL, whether reordered, and the
 *          workspace the pattern was built in: IW's address (two ints) and LIW
 *   IW: nnzA nnzL nz accepted last | Ap[n+1] Ai[nnzA] (the permuted upper triangle, every diagonal present) |
 *       Lp[n+1] Li[nnzL] | etree[n] Lnz[n] | perm[n] (P, for ma27cd) | iwork[3n] (QDLDL's) | bwork[n] (QDLDL's) |
 *       map[nz] (triplet -> Ai slot) | Rp[n+1] Ri[nnzL] (the rows of L's pattern, `QDLDL_rows`) |
 *       scratch for building the pattern [2 nz + 2 n]
 *   A: the triplets' values[nz] (written by IPOPT) | Ax[nnzA] | Lx[nnzL] | D[n] | Dinv[n] | fwork[n] | x[n]
 * The pattern of IW is built at the first factorisation of an analysis and reused by the next ones, so a
 * factorisation is a scatter of the values and QDLDL's numeric pass; the rows of L's pattern too, which QDLDL had
 * found again in every factorisation by walking the elimination tree (the same arithmetic in the same order: the
 * same factors to the bit). Whether IW holds this analysis's pattern is
 * recorded in IKEEP (IW's address and LIW when it was built), never read from IW itself: IPOPT allocates IW
 * anew for each analysis and does not clear it, so it may hold what an earlier analysis left there (a header that
 * matched and a stale map once scattered out of bounds: a screen solve's segfault, docs/decisions.md). IW's header
 * (nnzA, nnzL, nz) is for ma27cd, which is given IW but not IKEEP. Systems with n < RECORD are analysed anew
 * at every factorisation.
 *
 * A factorisation stops once it has more negative pivots than the last one IPOPT solved with (`accepted`, learnt
 * at ma27cd; -1 until then). IPOPT wants the same inertia at every factorisation of an analysis (one negative
 * eigenvalue per constraint), and the pivots so far are the inertia of a leading block, whose negative eigenvalues
 * cannot outnumber the whole matrix's (Cauchy interlacing): such a matrix has the wrong inertia whatever its other
 * pivots. It is reported with one negative pivot more than accepted (INFO(15)), the branch the full count takes
 * (too many, not too few), and IPOPT perturbs and factorises again as before. On the exploration problem 127 of a
 * solve's 232 factorisations have too many, the stop comes after two thirds of the work on median, and the
 * iteration costs 0.96x (docs/decisions.md, 2026-11-28). Not stopped: a matrix with a node whose row and column
 * are zero (a constraint row whose Jacobian row vanished), whose zero pivot the full factorisation reports as
 * singular, which IPOPT answers otherwise. A pivot that cancels to exactly zero after the stop is reported as too
 * many negative pivots instead: no solve of 1,920 exploration starts and 9 default runs changed, 2 of 12 main-job
 * starts to the iteration cap with every system by this library did. `last` is the negative pivots of the last
 * factorisation, -1 for a singular one, STOPPED for one stopped: IPOPT solves only with a factorisation whose
 * inertia it accepted, but should it solve with a stopped one, ma27cd finishes it first.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "amd.h"
#include "qdldl.h"

#define HDR 5 /* IW's header: nnzA, nnzL, nz, accepted, last */
#define ACCEPTED 3 /* IW's slot: negative pivots of the last factorisation solved with (-1: none yet) */
#define LAST 4 /* IW's slot: negative pivots of the last factorisation (-1: singular; STOPPED) */
#define STOPPED (-2)
#define RECORD 6 /* IKEEP's entries after P and Pinv that this uses: n >= RECORD keeps them */
#define WEAK 1e-7 /* a diagonal entry this small counts as zero for the ordering (IPOPT's delta_c <= 1e-8) */
#define MATCHED_FROM 1000 /* from this many rows a constraint row waits for its own neighbour (defer_zero_pivots) */

static int ints_needed(int n, int nz, int nnzA, int nnzL) {
    return HDR + (n + 1) + nnzA + (n + 1) + nnzL + n + n + n + 3 * n + n + nz + (n + 1) + nnzL + (2 * nz + 2 * n);
}

static int doubles_needed(int n, int nz, int nnzA, int nnzL) { return nz + nnzA + nnzL + 4 * n; }

/* The permuted upper triangle of the (1-based) triplets with every diagonal present, duplicates merged: its
 * columns Ap[n+1] and sorted rows Ai, and for each triplet its slot in Ai (map[nz]). Ai needs nz + n slots while it
 * is built. Returns nnzA, or -1 when out of memory. */
static int pattern(int n, int nz, const int *irn, const int *icn, const int *pinv, int *Ap, int *Ai, int *map) {
    int j, k, p, unique = 0;
    int *next = (int *)malloc(sizeof(int) * (n + 1));
    int *order = (int *)malloc(sizeof(int) * (nz + n + 1));
    int *slot = (int *)malloc(sizeof(int) * (nz + n + 1));
    int *rows = (int *)malloc(sizeof(int) * (nz + n + 1));
    int *counts = (int *)calloc(n + 1, sizeof(int));
    if (!next || !order || !slot || !rows || !counts) {
        free(next); free(order); free(slot); free(rows); free(counts);
        return -1;
    }
    for (j = 0; j <= n; j++) Ap[j] = 0;
    for (k = 0; k < nz; k++) {
        int a = pinv[irn[k] - 1], b = pinv[icn[k] - 1];
        Ap[(a > b ? a : b) + 1]++;
    }
    for (j = 0; j < n; j++) Ap[j + 1] += Ap[j] + 1; /* + the diagonal */
    for (j = 0; j < n; j++) { rows[Ap[j]] = j; next[j] = Ap[j] + 1; }
    for (k = 0; k < nz; k++) {
        int a = pinv[irn[k] - 1], b = pinv[icn[k] - 1];
        int col = a > b ? a : b;
        map[k] = next[col];
        rows[next[col]++] = a < b ? a : b;
    }
    /* each column's entries sorted by row (insertion sort: columns are short), duplicates merged */
    for (j = 0; j < n; j++) {
        int start = Ap[j], len = Ap[j + 1] - Ap[j], last = -1;
        for (p = 0; p < len; p++) {
            int key = start + p, q = p - 1;
            while (q >= 0 && rows[order[start + q]] > rows[key]) { order[start + q + 1] = order[start + q]; q--; }
            order[start + q + 1] = key;
        }
        for (p = 0; p < len; p++) {
            int s = order[start + p];
            if (rows[s] != last) { last = rows[s]; Ai[unique++] = last; }
            slot[s] = unique - 1;
        }
        counts[j + 1] = unique;
    }
    for (k = 0; k < nz; k++) map[k] = slot[map[k]];
    memcpy(Ap, counts, sizeof(int) * (n + 1));
    free(next); free(order); free(slot); free(rows); free(counts);
    return unique;
}

/* The off-diagonal pattern of both triangles of the (1-based) triplets as 0-based columns: Cp[n+1] (zeroed by the
 * caller) and Ci[2 nz]; with A and Cx given (else NULL), the triplets' values too, Cx[2 nz] beside Ci. fill[n+1] is
 * scratch. */
static void adjacency(int n, int nz, const int *IRN, const int *ICN, const double *A, int *Cp, int *Ci, double *Cx,
                      int *fill) {
    int j, k;
    for (k = 0; k < nz; k++) {
        int a = IRN[k] - 1, b = ICN[k] - 1;
        if (a != b) { Cp[b + 1]++; Cp[a + 1]++; }
    }
    for (j = 0; j < n; j++) Cp[j + 1] += Cp[j];
    memcpy(fill, Cp, sizeof(int) * (n + 1));
    for (k = 0; k < nz; k++) {
        int a = IRN[k] - 1, b = ICN[k] - 1;
        if (a == b) continue;
        if (Cx) { Cx[fill[b]] = A[k]; Cx[fill[a]] = A[k]; }
        Ci[fill[b]++] = a;
        Ci[fill[a]++] = b;
    }
}

/* For every zero-diagonal node (a constraint row), a neighbour of its own to be eliminated before it (match[u],
 * left at -1, as the caller set it, if none is left): a variable with a nonzero diagonal that no other constraint
 * row is given and that is not a dense column (more than n / 10 neighbours: the design joints, which AMD puts
 * last). Greedy, the rows with the fewest candidates first; each takes the candidate with the fewest constraint-row
 * neighbours (a slack, whose only one is its own row, before a joint), then the largest |a_uv| of the matrix given.
 * Cp, Ci, Cx: both triangles' off-diagonal pattern and values. Returns 0, or -1 when out of memory. */
static int own_neighbours(int n, const int *Cp, const int *Ci, const double *Cx, const char *zero, int *match) {
    int j, q, r, nrows = 0, dense = n / 10;
    int *zn = (int *)calloc(n, sizeof(int)), *rows = (int *)malloc(sizeof(int) * (n + 1));
    int *count = (int *)calloc(n, sizeof(int)), *bucket = (int *)calloc(n + 2, sizeof(int));
    char *taken = (char *)calloc(n, 1);
    if (!zn || !rows || !count || !bucket || !taken) {
        free(zn); free(rows); free(count); free(bucket); free(taken);
        return -1;
    }
    for (j = 0; j < n; j++)
        for (q = Cp[j]; q < Cp[j + 1]; q++)
            if (zero[Ci[q]]) zn[j]++;
    for (j = 0; j < n; j++) { /* each row's candidates, counted; then the rows by that count (a stable counting sort) */
        if (!zero[j]) continue;
        for (q = Cp[j]; q < Cp[j + 1]; q++)
            if (!zero[Ci[q]] && Cp[Ci[q] + 1] - Cp[Ci[q]] <= dense) count[j]++;
        bucket[count[j] + 1]++;
        nrows++;
    }
    for (j = 0; j <= n; j++) bucket[j + 1] += bucket[j];
    for (j = 0; j < n; j++)
        if (zero[j]) rows[bucket[count[j]]++] = j;
    for (r = 0; r < nrows; r++) {
        int u = rows[r], best = -1;
        double size = 0.0;
        for (q = Cp[u]; q < Cp[u + 1]; q++) {
            int v = Ci[q];
            double a = fabs(Cx[q]);
            if (zero[v] || taken[v] || Cp[v + 1] - Cp[v] > dense || a == 0.0) continue;
            if (best < 0 || zn[v] < zn[best] || (zn[v] == zn[best] && a > size)) { best = v; size = a; }
        }
        if (best >= 0) { match[u] = best; taken[best] = 1; }
    }
    free(zn); free(rows); free(count); free(bucket); free(taken);
    return 0;
}

/* The ordering P (new -> old) changed so that no node whose diagonal is zero (a constraint row of IPOPT's KKT
 * matrix, whether delta_c is 0 or 1e-8 mu^0.25) is eliminated before one of its neighbours: its pivot is then the
 * fill that neighbour left (-a_uv^2 / h) instead of an exact zero or -delta_c. From `MATCHED_FROM` rows on, the
 * neighbour must be the row's own (`own_neighbours`; a row without one waits for any): rows whose only eliminated
 * neighbour is the same variable (a waypoint's five tracking rows and one of its joints) leave a rank-one block
 * after it, the first row's pivot takes it and the others' fall to -delta_c (5.6e-11 at mu = 1e-9), whose fill
 * (1e10) leaves the design joints' pivots, eliminated last, without the digits their signs need: near
 * convergence a false wrong inertia on about half the factorisations of a 40-waypoint screen, and IPOPT
 * regularising every iteration (docs/decisions.md, 2026-11-28). Nodes keep AMD's order otherwise; a deferred node
 * follows the node that frees it. Returns 0, or -1 when out of memory. */
static int defer_zero_pivots(int n, int nz, const int *IRN, const int *ICN, const double *A, int *P, int *Pinv) {
    int j, k, q, placed = 0;
    double *diag = (double *)calloc(n, sizeof(double)), *Cx = (double *)malloc(sizeof(double) * (2 * nz + 1));
    char *zero = (char *)malloc(n), *done = (char *)calloc(n, 1), *waiting = (char *)calloc(n, 1);
    int *Cp = (int *)calloc(n + 1, sizeof(int)), *Ci = (int *)malloc(sizeof(int) * (2 * nz + 1));
    int *fill = (int *)malloc(sizeof(int) * (n + 1)), *order = (int *)malloc(sizeof(int) * (n + 1));
    int *stack = (int *)malloc(sizeof(int) * (2 * nz + n + 1)), *match = (int *)malloc(sizeof(int) * (n + 1));
    int status = -1;
    if (!diag || !Cx || !zero || !done || !waiting || !Cp || !Ci || !fill || !order || !stack || !match) goto out;
    for (k = 0; k < nz; k++)
        if (IRN[k] == ICN[k]) diag[IRN[k] - 1] += A[k];
    /* zero, or as good as zero: a regularised constraint row's -delta_c (1e-8 mu^0.25) is no pivot to divide by */
    for (j = 0; j < n; j++) zero[j] = fabs(diag[j]) <= WEAK;
    adjacency(n, nz, IRN, ICN, A, Cp, Ci, n >= MATCHED_FROM ? Cx : NULL, fill); /* values only to match with */
    for (j = 0; j < n; j++) match[j] = -1;
    if (n >= MATCHED_FROM) {
        if (own_neighbours(n, Cp, Ci, Cx, zero, match) < 0) goto out;
    }
    for (j = 0; j < n; j++) {
        int top = 0;
        stack[top++] = P[j];
        while (top > 0) { /* a node, then every waiting node it may free, in turn */
            int u = stack[--top], partner = -1;
            if (done[u]) continue;
            if (zero[u]) { /* waits for its own neighbour, or for any eliminated one if it has none */
                if (match[u] >= 0)
                    partner = done[match[u]] ? match[u] : -1;
                else
                    for (q = Cp[u]; q < Cp[u + 1] && partner < 0; q++)
                        if (done[Ci[q]]) partner = Ci[q];
                if (partner < 0) { waiting[u] = 1; continue; }
            }
            done[u] = 1;
            waiting[u] = 0;
            order[placed++] = u;
            for (q = Cp[u]; q < Cp[u + 1]; q++)
                if (waiting[Ci[q]]) stack[top++] = Ci[q];
        }
    }
    for (j = 0; j < n; j++) /* nodes nothing freed: where AMD put them, at the end */
        if (!done[P[j]]) { done[P[j]] = 1; order[placed++] = P[j]; }
    memcpy(P, order, sizeof(int) * n);
    for (j = 0; j < n; j++) Pinv[P[j]] = j;
    status = 0;
out:
    free(diag); free(Cx); free(zero); free(done); free(waiting); free(Cp); free(Ci); free(fill); free(order);
    free(stack); free(match);
    return status;
}

/* nnzA and nnzL of ordering Pinv, or -1. */
static int factor_sizes(int n, int nz, const int *IRN, const int *ICN, const int *Pinv, int *nnzA, int *nnzL) {
    int *Ap = (int *)malloc(sizeof(int) * (n + 1)), *Ai = (int *)malloc(sizeof(int) * (nz + n + 1));
    int *map = (int *)malloc(sizeof(int) * (nz + 1)), *work = (int *)malloc(sizeof(int) * (n + 1));
    int *Lnz = (int *)malloc(sizeof(int) * (n + 1)), *etree = (int *)malloc(sizeof(int) * (n + 1));
    *nnzA = (Ap && Ai && map && work && Lnz && etree) ? pattern(n, nz, IRN, ICN, Pinv, Ap, Ai, map) : -1;
    *nnzL = *nnzA >= 0 ? QDLDL_etree(n, Ap, Ai, work, Lnz, etree) : -1;
    free(Ap); free(Ai); free(map); free(work); free(Lnz); free(etree);
    return *nnzL < 0 ? -1 : 0;
}

/* An analysis's record (IKEEP after P and Pinv) of the workspace its pattern was built in: IW's address, split in
 * two ints, and LIW (NULL, 0: none). Within one analysis IPOPT only ever replaces IW by a larger one. */
static void record_workspace(int *record, const int *IW, int LIW) {
    unsigned long long address = (unsigned long long)(size_t)IW;
    record[3] = (int)(unsigned)(address & 0xffffffffu);
    record[4] = (int)(unsigned)(address >> 32);
    record[5] = LIW;
}

static int built_in(const int *record, const int *IW, int LIW) {
    unsigned long long address = (unsigned long long)(size_t)IW;
    return IW != NULL && record[5] == LIW && record[3] == (int)(unsigned)(address & 0xffffffffu) &&
           record[4] == (int)(unsigned)(address >> 32);
}

static void ma27i(int *ICNTL, double *CNTL) {
    memset(ICNTL, 0, 30 * sizeof(int));
    memset(CNTL, 0, 5 * sizeof(double));
    CNTL[0] = 0.1;
}

static void ma27a(int *N, int *NZ, const int *IRN, const int *ICN, int *IKEEP, int *NSTEPS, int *INFO, double *OPS) {
    int n = *N, nz = *NZ, j, status, nnzA, nnzL;
    double control[AMD_CONTROL], info[AMD_INFO];
    int *P = IKEEP, *Pinv = IKEEP + n;
    memset(INFO, 0, 20 * sizeof(int));
    *NSTEPS = 1;
    /* AMD on the pattern of both triangles */
    int *Cp = (int *)calloc(n + 1, sizeof(int)), *Ci = (int *)malloc(sizeof(int) * (2 * nz + 1));
    int *fill = (int *)malloc(sizeof(int) * (n + 1));
    if (!Cp || !Ci || !fill) { free(Cp); free(Ci); free(fill); INFO[0] = -1; return; }
    adjacency(n, nz, IRN, ICN, NULL, Cp, Ci, NULL, fill);
    amd_defaults(control);
    status = amd_order(n, Cp, Ci, P, control, info);
    free(Cp); free(Ci); free(fill);
    if (status < 0) { INFO[0] = -1; return; }
    for (j = 0; j < n; j++) Pinv[P[j]] = j;
    /* the sizes of the factors, for the workspace IPOPT allocates (ma27b may reorder and ask for more) */
    if (factor_sizes(n, nz, IRN, ICN, Pinv, &nnzA, &nnzL) < 0) { INFO[0] = -1; return; }
    if (n >= RECORD) {
        IKEEP[2 * n] = nnzA;
        IKEEP[2 * n + 1] = nnzL;
        IKEEP[2 * n + 2] = 0; /* not yet reordered for the first matrix's zero diagonal */
        record_workspace(IKEEP + 2 * n, NULL, 0); /* no pattern built yet */
    }
    *OPS = (double)nnzL;
    INFO[4] = doubles_needed(n, nz, nnzA, nnzL);
    INFO[5] = ints_needed(n, nz, nnzA, nnzL);
}

static void ma27b(int *N, int *NZ, const int *IRN, const int *ICN, double *A, int *LA, int *IW, int *LIW,
                  int *IKEEP, int *MAXFRT, int *INFO) {
    int n = *N, nz = *NZ, k, pos, nnzA, nnzL;
    int *record = n >= RECORD ? IKEEP + 2 * n : NULL;
    memset(INFO, 0, 20 * sizeof(int));
    if (record && record[2] == 0) { /* the first matrix of this analysis: its zero diagonal decides the order */
        if (defer_zero_pivots(n, nz, IRN, ICN, A, IKEEP, IKEEP + n) < 0 ||
            factor_sizes(n, nz, IRN, ICN, IKEEP + n, &nnzA, &nnzL) < 0) { INFO[0] = -1; return; }
        record[0] = nnzA;
        record[1] = nnzL;
        record[2] = 1;
    }
    const int *Pinv = IKEEP + n;
    if (record) {
        nnzA = record[0];
        nnzL = record[1];
    } else if (factor_sizes(n, nz, IRN, ICN, Pinv, &nnzA, &nnzL) < 0) {
        INFO[0] = -1;
        return;
    }
    int ineed = ints_needed(n, nz, nnzA, nnzL), dneed = doubles_needed(n, nz, nnzA, nnzL);
    *MAXFRT = 1;
    if (*LIW < ineed) { INFO[0] = -3; INFO[1] = ineed; return; }
    if (*LA < dneed) { INFO[0] = -4; INFO[1] = dneed; return; }
    int *Ap = IW + HDR, *Ai = Ap + (n + 1), *Lp = Ai + nnzA, *Li = Lp + (n + 1), *etree = Li + nnzL;
    int *Lnz = etree + n, *perm = Lnz + n, *iwork = perm + n, *bwork = iwork + 3 * n, *map = bwork + n;
    int *Rp = map + nz, *Ri = Rp + (n + 1), *scratch = Ri + nnzL; /* scratch: 2 nz + 2 n */
    if (!(record && built_in(record, IW, *LIW))) {
        if (pattern(n, nz, IRN, ICN, Pinv, Ap, scratch, map) != nnzA) { INFO[0] = -1; return; }
        memcpy(Ai, scratch, sizeof(int) * nnzA);
        if (QDLDL_etree(n, Ap, Ai, iwork, Lnz, etree) != nnzL) { INFO[0] = -1; return; }
        if (QDLDL_rows(n, Ap, Ai, etree, Rp, Ri, bwork, iwork) != nnzL) { INFO[0] = -1; return; }
        IW[0] = nnzA; IW[1] = nnzL;
        IW[ACCEPTED] = -1; /* nothing solved with yet in this analysis */
        if (record) record_workspace(record, IW, *LIW);
    }
    IW[2] = nz;
    memcpy(perm, IKEEP, sizeof(int) * n); /* for ma27cd, which is not given IKEEP */
    double *Ax = A + nz, *Lx = Ax + nnzA, *D = Lx + nnzL, *Dinv = D + n, *fwork = Dinv + n;
    memset(Ax, 0, sizeof(double) * nnzA);
    for (k = 0; k < nz; k++) Ax[map[k]] += A[k];
    int limit = IW[ACCEPTED], j, p;
    if (limit >= 0) { /* a node whose row and column are zero here has a zero pivot: the factorisation must find it */
        memset(bwork, 0, sizeof(int) * n); /* QDLDL sets bwork up again */
        for (j = 0; j < n; j++)
            for (p = Ap[j]; p < Ap[j + 1]; p++)
                if (Ax[p] != 0.0) bwork[j] = bwork[Ai[p]] = 1;
        for (j = 0; j < n && limit >= 0; j++)
            if (!bwork[j]) limit = -1;
    }
    pos = QDLDL_factor(n, Ap, Ai, Ax, Lp, Li, Lx, D, Dinv, Lnz, Rp, Ri, iwork, fwork, limit);
    INFO[8] = nnzL;
    INFO[9] = nnzL;
    if (pos == -1) { INFO[0] = -5; INFO[1] = n - 1; IW[LAST] = -1; return; }
    IW[LAST] = pos == STOPPED ? STOPPED : n - pos;
    INFO[14] = pos == STOPPED ? limit + 1 : n - pos; /* negative eigenvalues: the negative entries of D */
}

static void ma27c(int *N, double *A, int *IW, double *RHS) {
    int n = *N, i;
    int nnzA = IW[0], nnzL = IW[1], nz = IW[2];
    int *Ap = IW + HDR, *Ai = Ap + (n + 1), *Lp = Ai + nnzA, *Li = Lp + (n + 1), *etree = Li + nnzL;
    int *Lnz = etree + n, *P = Lnz + n, *iwork = P + n, *bwork = iwork + 3 * n, *map = bwork + n;
    int *Rp = map + nz, *Ri = Rp + (n + 1);
    double *Ax = A + nz, *Lx = Ax + nnzA, *D = Lx + nnzL, *Dinv = D + n, *fwork = Dinv + n, *x = fwork + n;
    if (IW[LAST] == STOPPED) { /* solved with although stopped early: finish it */
        int pos = QDLDL_factor(n, Ap, Ai, Ax, Lp, Li, Lx, D, Dinv, Lnz, Rp, Ri, iwork, fwork, -1);
        IW[LAST] = pos >= 0 ? n - pos : -1;
    }
    if (IW[LAST] >= 0) IW[ACCEPTED] = IW[LAST];
    for (i = 0; i < n; i++) x[i] = RHS[P[i]];
    QDLDL_solve(n, Lp, Li, Lx, Dinv, x);
    for (i = 0; i < n; i++) RHS[P[i]] = x[i];
}

/* The Fortran-style entry points, with and without the trailing underscore IPOPT's loader may look for. */
#define MA27ID_ARGS int *ICNTL, double *CNTL
#define MA27AD_ARGS                                                                                                   \
    int *N, int *NZ, const int *IRN, const int *ICN, int *IW, int *LIW, int *IKEEP, int *IW1, int *NSTEPS,           \
        int *IFLAG, int *ICNTL, double *CNTL, int *INFO, double *OPS
#define MA27BD_ARGS                                                                                                   \
    int *N, int *NZ, const int *IRN, const int *ICN, double *A, int *LA, int *IW, int *LIW, int *IKEEP, int *NSTEPS, \
        int *MAXFRT, int *IW1, int *ICNTL, double *CNTL, int *INFO
#define MA27CD_ARGS                                                                                                   \
    int *N, double *A, int *LA, int *IW, int *LIW, double *W, int *MAXFRT, double *RHS, int *IW1, int *NSTEPS,       \
        int *ICNTL, int *INFO

void ma27id(MA27ID_ARGS) { ma27i(ICNTL, CNTL); }
void ma27id_(MA27ID_ARGS) { ma27i(ICNTL, CNTL); }
void ma27ad(MA27AD_ARGS) {
    (void)IW; (void)LIW; (void)IW1; (void)IFLAG; (void)ICNTL; (void)CNTL;
    ma27a(N, NZ, IRN, ICN, IKEEP, NSTEPS, INFO, OPS);
}
void ma27ad_(MA27AD_ARGS) { ma27ad(N, NZ, IRN, ICN, IW, LIW, IKEEP, IW1, NSTEPS, IFLAG, ICNTL, CNTL, INFO, OPS); }
void ma27bd(MA27BD_ARGS) {
    (void)NSTEPS; (void)IW1; (void)ICNTL; (void)CNTL;
    ma27b(N, NZ, IRN, ICN, A, LA, IW, LIW, IKEEP, MAXFRT, INFO);
}
void ma27bd_(MA27BD_ARGS) { ma27bd(N, NZ, IRN, ICN, A, LA, IW, LIW, IKEEP, NSTEPS, MAXFRT, IW1, ICNTL, CNTL, INFO); }
void ma27cd(MA27CD_ARGS) {
    (void)LA; (void)LIW; (void)W; (void)MAXFRT; (void)IW1; (void)NSTEPS; (void)ICNTL; (void)INFO;
    ma27c(N, A, IW, RHS);
}
void ma27cd_(MA27CD_ARGS) { ma27cd(N, A, LA, IW, LIW, W, MAXFRT, RHS, IW1, NSTEPS, ICNTL, INFO); }

#include "solver/hessenberg_transfer.h"

#include <cmath>
#include <utility>

#include "base/wide_simd.h"
#include "solver/dense_lapack.h"

namespace isolink {

namespace {

// One thread's work arrays for HessenbergTransfer::at.
struct Work {
  std::vector<double> re, im;                 // the shifted matrix, row-major, real and imaginary
  std::vector<double> xr, xi;                 // at_by_sources: the solution, q per source
  std::vector<std::complex<double>> mult;     // at_by_probes: the elimination's multipliers
  std::vector<char> swapped;                  // and its row swaps
  std::vector<std::complex<double>> c, u, w;  // at_by_probes: the probes' rows, U's block, w
};

Work& work() {
  thread_local Work w;
  return w;
}

}  // namespace

StatusOr<ShiftInvert> shift_invert(const Eigen::MatrixXd& g, const Eigen::MatrixXd& c,
                                   const Eigen::MatrixXd& b, double sigma) {
  const Eigen::Index q = c.cols();
  Eigen::MatrixXd rhs(q, q + b.cols());
  rhs << c, b;
  StatusOr<Eigen::MatrixXd> x = dense_solve(g + sigma * c, std::move(rhs));
  if (!x || !x->allFinite())
    return Status::Error("reduced model: the projected system is singular");
  return ShiftInvert{x->leftCols(q), x->rightCols(b.cols())};
}

Status HessenbergTransfer::set(const Eigen::MatrixXd& g, const Eigen::MatrixXd& c,
                               const Eigen::MatrixXd& b, const Eigen::MatrixXd& l, double sigma) {
  q_ = static_cast<int>(g.rows());
  sigma_ = sigma;
  lq_.resize(l.rows(), q_);
  qab_.resize(q_, b.cols());
  if (q_ == 0) return Status::Ok();
  StatusOr<ShiftInvert> si = shift_invert(g, c, b, sigma);
  if (!si) return si.status();
  StatusOr<DenseHessenberg> hd = dense_hessenberg(si->m);
  if (!hd) return hd.status();
  t_ = hd->h();
  // Q applied as its Householder reflections, never formed (4/3 q^3 flops saved: a sixth of
  // set() at order 900).
  lq_ = l;
  hd->apply_q(&lq_);
  qab_ = si->ab;
  hd->apply_q_transposed(&qab_);
  return Status::Ok();
}

StatusOr<ModalSplit> HessenbergTransfer::modes(double relative, double absolute) const {
  const Eigen::MatrixXd t = t_;
  return modal_split(t, qab_, lq_, relative, absolute, MatrixShape::Hessenberg);
}

Eigen::MatrixXcd HessenbergTransfer::at(std::complex<double> s) const {
  if (q_ == 0) return Eigen::MatrixXcd::Zero(qab_.cols(), lq_.rows());
  return lq_.rows() <= qab_.cols() ? at_by_probes(s.real() - sigma_, s.imag())
                                   : at_by_sources(s.real() - sigma_, s.imag());
}

// With A = I + z T eliminated as E A = U (E the row swaps and multipliers, U upper triangular),
// H_kp = y_p' Q'A^-1B_k where A' y_p = (L Q)_p', that is U' w_p = (L Q)_p' and y_p = E' w_p.
// U's rows come out of the elimination one at a time (two row buffers, T read once), in the
// order the forward substitution of U' w = c uses them, kBlock at a time: the block's rows kept,
// every probe's w over the block found from the block's triangle, and c past the block updated
// by one complex matrix product (the rest x kBlock by kBlock x np: BLAS zgemm) instead of np
// row updates per row of U (the 44.5 m link's model: its check's frequencies, a third of the
// model's time, in 1.5 s instead of 2.4). Cost per frequency about (9 + 8 (np - 1)) q^2 flops,
// most of it in the product, against 12 q^2 + 4 q^2 (nk - 1) for the sources' path below.
ISOLINK_WIDE_SIMD Eigen::MatrixXcd HessenbergTransfer::at_by_probes(double zr, double zi) const {
  constexpr int kBlock = 32;
  using Cplx = std::complex<double>;
  const int q = q_, np = static_cast<int>(lq_.rows());
  Work& ws = work();
  ws.re.resize(4 * static_cast<size_t>(q));
  double *ar = ws.re.data(), *ai = ar + q, *br = ai + q, *bi = br + q;  // rows j and j + 1
  ws.c.resize(static_cast<size_t>(q) * np);       // c (q x np), then w, then y
  ws.u.resize(static_cast<size_t>(q) * kBlock);   // the block's rows of U as columns (q x kBlock)
  ws.w.resize(static_cast<size_t>(kBlock) * np);  // the probes' w over the block
  Eigen::Map<Eigen::MatrixXcd> c(ws.c.data(), q, np);
  c = lq_.transpose().cast<Cplx>();
  auto u = [&](int r, int col) -> Cplx& { return ws.u[col + static_cast<size_t>(r) * q]; };
  ws.mult.resize(q);
  ws.swapped.resize(q);
  auto shifted_row = [&](int i, double* r, double* m) {  // row i of I + z T, from column i - 1
    const double* t = t_.data() + static_cast<size_t>(i) * q;
    for (int col = std::max(0, i - 1); col < q; ++col) r[col] = zr * t[col], m[col] = zi * t[col];
    r[i] += 1.0;
  };
  shifted_row(0, ar, ai);
  for (int j0 = 0; j0 < q; j0 += kBlock) {
    const int rows = std::min(kBlock, q - j0), past = j0 + rows;
    for (int j = j0; j < past; ++j) {  // rows j0 .. past - 1 of U
      if (j + 1 < q) {
        shifted_row(j + 1, br, bi);
        ws.swapped[j] = br[j] * br[j] + bi[j] * bi[j] > ar[j] * ar[j] + ai[j] * ai[j];
        if (ws.swapped[j]) std::swap(ar, br), std::swap(ai, bi);
        const Cplx l = Cplx(br[j], bi[j]) / Cplx(ar[j], ai[j]);
        ws.mult[j] = l;
        const double lr = l.real(), li = l.imag();
        for (int col = j + 1; col < q; ++col) {
          br[col] -= lr * ar[col] - li * ai[col];
          bi[col] -= lr * ai[col] + li * ar[col];
        }
      }
      for (int col = j; col < q; ++col) u(j - j0, col) = {ar[col], ai[col]};
      std::swap(ar, br), std::swap(ai, bi);
    }
    // The block's triangle: w_j = c_j / u_jj, taken from c_j' for j < j' < past.
    Eigen::Map<Eigen::MatrixXcd> w(ws.w.data(), rows, np);
    for (int j = j0; j < past; ++j) {
      const Cplx inv = 1.0 / u(j - j0, j);
      for (int p = 0; p < np; ++p) {
        const Cplx wj = c(j, p) * inv;
        c(j, p) = wj;
        w(j - j0, p) = wj;
        for (int col = j + 1; col < past; ++col) c(col, p) -= wj * u(j - j0, col);
      }
    }
    // c past the block -= U(block, past ..)' w.
    if (past < q) {
      using Strided = Eigen::Map<Eigen::MatrixXcd, 0, Eigen::OuterStride<>>;
      const Strided ub(&u(0, past), q - past, rows, Eigen::OuterStride<>(q));
      Strided rest(&c(past, 0), q - past, np, Eigen::OuterStride<>(q));
      dense_multiply(false, Cplx(-1.0), ub, w, Cplx(1.0), rest);
    }
  }
  // y = E' w: E = E_{q-2} ... E_0 with E_j = (I - l_j e_{j+1} e_j') P_j, so E' applies E_j'
  // from j = q - 2 down: w_j -= l_j w_{j+1}, then rows j and j + 1 swapped where P_j swapped.
  for (int j = q - 2; j >= 0; --j) {
    c.row(j) -= ws.mult[j] * c.row(j + 1);
    if (ws.swapped[j]) c.row(j).swap(c.row(j + 1));
  }
  return qab_.transpose().cast<Cplx>() * c;  // nk x np
}

// (I + z T) x = Q' A^-1 B by elimination down the subdiagonal (rows j and j + 1 swapped where
// the lower one's entry is larger), then back substitution. Only the Hessenberg part of the
// work array is touched. The arithmetic is written out in real and imaginary parts so that the
// row updates vectorise.
ISOLINK_WIDE_SIMD Eigen::MatrixXcd HessenbergTransfer::at_by_sources(double zr, double zi) const {
  const int q = q_, nk = static_cast<int>(qab_.cols()), np = static_cast<int>(lq_.rows());
  Eigen::MatrixXcd h(nk, np);
  Work& ws = work();
  ws.re.resize(static_cast<size_t>(q) * q);
  ws.im.resize(static_cast<size_t>(q) * q);
  double* re = ws.re.data();
  double* im = ws.im.data();
  for (int i = 0; i < q; ++i) {
    const int from = std::max(0, i - 1);
    const double* t = t_.data() + static_cast<size_t>(i) * q;
    double* r = re + static_cast<size_t>(i) * q;
    double* m = im + static_cast<size_t>(i) * q;
    for (int j = from; j < q; ++j) r[j] = zr * t[j], m[j] = zi * t[j];
    r[i] += 1.0;
  }
  Eigen::MatrixXcd x = qab_.cast<std::complex<double>>();  // q x nk, becomes the solution
  for (int j = 0; j + 1 < q; ++j) {
    double* r0 = re + static_cast<size_t>(j) * q;
    double* m0 = im + static_cast<size_t>(j) * q;
    double* r1 = r0 + q;
    double* m1 = m0 + q;
    if (r1[j] * r1[j] + m1[j] * m1[j] > r0[j] * r0[j] + m0[j] * m0[j]) {
      for (int c = j; c < q; ++c) std::swap(r0[c], r1[c]), std::swap(m0[c], m1[c]);
      x.row(j).swap(x.row(j + 1));
    }
    const std::complex<double> lj =
        std::complex<double>(r1[j], m1[j]) / std::complex<double>(r0[j], m0[j]);
    const double lr = lj.real(), li = lj.imag();
    for (int c = j + 1; c < q; ++c) {
      r1[c] -= lr * r0[c] - li * m0[c];
      m1[c] -= lr * m0[c] + li * r0[c];
    }
    x.row(j + 1) -= lj * x.row(j);
  }
  // Back substitution, every source at once (one pass over the triangle), on the solution's
  // real and imaginary parts kept apart (contiguous, so that the dot products vectorise).
  ws.xr.resize(static_cast<size_t>(q) * nk);
  ws.xi.resize(static_cast<size_t>(q) * nk);
  for (int k = 0; k < nk; ++k)
    for (int i = 0; i < q; ++i)
      ws.xr[k * q + i] = x(i, k).real(), ws.xi[k * q + i] = x(i, k).imag();
  for (int i = q - 1; i >= 0; --i) {
    const double* r = re + static_cast<size_t>(i) * q;
    const double* m = im + static_cast<size_t>(i) * q;
    for (int k = 0; k < nk; ++k) {
      const double* vr = ws.xr.data() + static_cast<size_t>(k) * q;
      const double* vi = ws.xi.data() + static_cast<size_t>(k) * q;
      double sr = vr[i], si = vi[i];
      for (int c = i + 1; c < q; ++c) {
        sr -= r[c] * vr[c] - m[c] * vi[c];
        si -= r[c] * vi[c] + m[c] * vr[c];
      }
      const std::complex<double> xi =
          std::complex<double>(sr, si) / std::complex<double>(r[i], m[i]);
      ws.xr[k * q + i] = xi.real();
      ws.xi[k * q + i] = xi.imag();
    }
  }
  for (int k = 0; k < nk; ++k)
    for (int i = 0; i < q; ++i) x(i, k) = std::complex<double>(ws.xr[k * q + i], ws.xi[k * q + i]);
  for (int k = 0; k < nk; ++k)
    for (int p = 0; p < np; ++p) h(k, p) = lq_.row(p).cast<std::complex<double>>().dot(x.col(k));
  return h;
}

}  // namespace isolink

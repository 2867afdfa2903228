/* element.h: one linear tetrahedron's co-rotational mechanics (ARCHITECTURE.md, "The physics").
 * Shared by the CPU reference (double) and the device kernels (float): written once here.
 *
 * Conventions
 * - Corners p[3*corner + axis], corner order as in the mesh (positively oriented).
 * - frame[9] is row-major 3x3; its rows are the element frame's axes in world coordinates,
 *   so frame maps world vectors to frame coordinates (SOFA's QR-style "large" method):
 *   x along edge 0-1, z along the normal of face 0-1-2, y = z x x.
 *   The element rotation R of the design notes (frame coordinates -> world) is frame^T.
 * - grad[12]: grad[3*c + j] is the gradient of corner c's shape function with respect to
 *   coordinate j of the element's REST frame (constant over the element).
 * - vlambda, vmu: the element volume times the Lame coefficients lambda and mu.
 * - Units: metres, newtons, pascals.
 *
 * Why no 12x12 K_e: the rest stiffness K_e = V B^T D B is applied in this factored form,
 * which is the same matrix to rounding (tests/reference/element_test.cpp) but costs about
 * 270 flops instead of 430 and reads 15 numbers per element instead of 78:
 *   H = F * sum_c d_c grad_c^T           (displacement gradient in the element frame, F = frame)
 *   sigma = lambda tr(H) I + mu (H + H^T) (linear isotropic stress of the small strain sym(H))
 *   y_c = V F^T sigma grad_c             (nodal forces, rotated back to the world)
 * SOFA's GPU tetrahedron keeps the same 15 numbers per element for the same reason. */
#ifndef SIGMAFEM_ELEMENT_H
#define SIGMAFEM_ELEMENT_H

#include "dialect.h"

/* The frame of the QR-style rotation (see the file comment); the corners need not be at rest. */
SF_FN void sf_element_frame(SF_IN(p, 12), SF_OUT(frame, 9)) {
  SF_REAL ex[3];
  SF_REAL ey[3];
  SF_REAL ez[3];
  SF_UNROLL
  for (int k = 0; k < 3; ++k) {
    ex[k] = p[3 + k] - p[k];
    ey[k] = p[6 + k] - p[k];
  }
  SF_REAL nx = SF_SQRT(ex[0] * ex[0] + ex[1] * ex[1] + ex[2] * ex[2]);
  SF_UNROLL
  for (int k = 0; k < 3; ++k) ex[k] /= nx;
  ez[0] = ex[1] * ey[2] - ex[2] * ey[1];
  ez[1] = ex[2] * ey[0] - ex[0] * ey[2];
  ez[2] = ex[0] * ey[1] - ex[1] * ey[0];
  SF_REAL nz = SF_SQRT(ez[0] * ez[0] + ez[1] * ez[1] + ez[2] * ez[2]);
  SF_UNROLL
  for (int k = 0; k < 3; ++k) ez[k] /= nz;
  /* y = z x x is already unit length: z and x are orthonormal. */
  ey[0] = ez[1] * ex[2] - ez[2] * ex[1];
  ey[1] = ez[2] * ex[0] - ez[0] * ex[2];
  ey[2] = ez[0] * ex[1] - ez[1] * ex[0];
  SF_UNROLL
  for (int k = 0; k < 3; ++k) {
    frame[k] = ex[k];
    frame[3 + k] = ey[k];
    frame[6 + k] = ez[k];
  }
}

/* A frame's third row from its first two, z = x cross y: the QR and the polar frames are both
 * right-handed and orthonormal (to rounding). For back ends that keep two rows of each frame
 * (Vulkan: kernels/vulkan/ensemble_layout.h's SF_FRAME_ROWS_KEPT). */
SF_FN void sf_frame_third_row(SF_INOUT(frame, 9)) {
  frame[6] = frame[1] * frame[5] - frame[2] * frame[4];
  frame[7] = frame[2] * frame[3] - frame[0] * frame[5];
  frame[8] = frame[0] * frame[4] - frame[1] * frame[3];
}

/* y_c = F^T S grad_c for the four corners, with S = V sigma(H) and H = F G (file comment).
 * `G` is sum_c v_c grad_c^T in world-by-rest-frame coordinates; `identity_shift` is 1 when
 * G comes from positions (the rest shape is subtracted: H - I is the co-rotational strain's
 * displacement gradient), 0 when it comes from a displacement. `sign` is -1 for forces. */
SF_FN void sf_element_stress_divergence(SF_IN(frame, 9), SF_IN(grad, 12), SF_REAL vlambda,
                                        SF_REAL vmu, SF_IN(G, 9), SF_REAL identity_shift,
                                        SF_REAL sign, SF_OUT(y, 12)) {
  SF_REAL H[9];
  SF_UNROLL
  for (int r = 0; r < 3; ++r) {
    SF_UNROLL
    for (int j = 0; j < 3; ++j) {
      H[3 * r + j] = frame[3 * r] * G[j] + frame[3 * r + 1] * G[3 + j] +
                     frame[3 * r + 2] * G[6 + j];
    }
  }
  H[0] -= identity_shift;
  H[4] -= identity_shift;
  H[8] -= identity_shift;
  SF_REAL pressure = vlambda * (H[0] + H[4] + H[8]);
  SF_REAL S[9]; /* V sigma, symmetric */
  SF_UNROLL
  for (int r = 0; r < 3; ++r) {
    SF_UNROLL
    for (int j = 0; j < 3; ++j) S[3 * r + j] = vmu * (H[3 * r + j] + H[3 * j + r]);
    S[4 * r] += pressure;
  }
  SF_REAL T[9]; /* sign * F^T S: the stress rotated back to the world, row index world */
  SF_UNROLL
  for (int k = 0; k < 3; ++k) {
    SF_UNROLL
    for (int j = 0; j < 3; ++j) {
      T[3 * k + j] = sign * (frame[k] * S[j] + frame[3 + k] * S[3 + j] + frame[6 + k] * S[6 + j]);
    }
  }
  SF_UNROLL
  for (int c = 0; c < 4; ++c) {
    SF_UNROLL
    for (int k = 0; k < 3; ++k) {
      y[3 * c + k] = T[3 * k] * grad[3 * c] + T[3 * k + 1] * grad[3 * c + 1] +
                     T[3 * k + 2] * grad[3 * c + 2];
    }
  }
}

/* G = sum_c v_c grad_c^T for corner values v relative to corner 0 when `relative` is 1.
 * Relative values keep float32 rounding at the element's size, not the organ's position
 * (the shape-function gradients sum to zero, so the result is the same in exact arithmetic). */
SF_FN void sf_element_gradient(SF_IN(grad, 12), SF_IN(v, 12), SF_REAL relative, SF_OUT(G, 9)) {
  SF_UNROLL
  for (int i = 0; i < 9; ++i) G[i] = SF_LIT(0.0);
  SF_UNROLL
  for (int c = 0; c < 4; ++c) {
    SF_UNROLL
    for (int i = 0; i < 3; ++i) {
      SF_REAL value = v[3 * c + i] - relative * v[i];
      SF_UNROLL
      for (int j = 0; j < 3; ++j) G[3 * i + j] += value * grad[3 * c + j];
    }
  }
}

/* The cofactor matrix of the row-major 3x3 X divided by det X, which is X^-T, into Y; returns
 * det X (Y is zero when it is 0). */
SF_FN SF_REAL sf_inverse_transpose3(SF_IN(X, 9), SF_OUT(Y, 9)) {
  SF_REAL C[9];
  C[0] = X[4] * X[8] - X[5] * X[7];
  C[1] = X[5] * X[6] - X[3] * X[8];
  C[2] = X[3] * X[7] - X[4] * X[6];
  C[3] = X[2] * X[7] - X[1] * X[8];
  C[4] = X[0] * X[8] - X[2] * X[6];
  C[5] = X[1] * X[6] - X[0] * X[7];
  C[6] = X[1] * X[5] - X[2] * X[4];
  C[7] = X[2] * X[3] - X[0] * X[5];
  C[8] = X[0] * X[4] - X[1] * X[3];
  SF_REAL det = X[0] * C[0] + X[1] * C[1] + X[2] * C[2];
  SF_REAL inverse = SF_SELECT(SF_NONZERO(det), SF_LIT(1.0) / det, SF_LIT(0.0));
  SF_UNROLL
  for (int i = 0; i < 9; ++i) Y[i] = C[i] * inverse;
  return det;
}

/* Newton steps of the polar decomposition: the iteration converges quadratically (an error e
 * becomes about e^2 / 2), with the Frobenius scaling from e below 0.5 (strains up to 50%) to
 * float64 rounding in 5 steps (Higham, "Computing the polar decomposition", 1986). A fixed
 * count, unrolled: the device compilers keep the 3x3s in registers and vectorise across
 * elements, which a loop that stops when converged would prevent. */
#define SF_POLAR_STEPS 5

/* The frame of the polar rotation: G = sum_c p_c grad_c^T is the element's deformation
 * gradient (world by rest-frame coordinates), G = R U its polar decomposition (R a rotation,
 * U symmetric positive definite), and frame = R^T, so that H = frame G = U is the element's
 * stretch: unlike the QR frame it does not depend on which edge comes first, and the elastic
 * forces it gives have no net torque (angular momentum is kept), which the QR frame loses
 * at large strain near nu = 0.5 (README, "The physics"). SOFA's "polar" method. R comes
 * from Higham's scaled Newton iteration X <- (g X + X^-T / g) / 2, X_0 = G,
 * g = (|X^-1|_F / |X|_F)^(1/2). An inverted or flat element (det G <= 0) has no rotation of
 * that kind: it keeps the QR frame (selected, not branched to, so that the code stays
 * straight for the vectorisers; its iteration runs on the identity). At rest G is the rest
 * frame's transpose, already orthogonal: the frame is the QR frame to rounding. */
SF_FN void sf_element_polar_frame(SF_IN(grad, 12), SF_IN(p, 12), SF_OUT(frame, 9)) {
  SF_REAL X[9];
  SF_REAL Y[9];
  SF_REAL qr[9];
  sf_element_frame(p, qr);
  sf_element_gradient(grad, p, SF_LIT(1.0), X);
  SF_REAL proper = SF_SELECT(SF_POSITIVE(sf_inverse_transpose3(X, Y)), SF_LIT(1.0), SF_LIT(0.0));
  SF_UNROLL
  for (int i = 0; i < 9; ++i) {
    X[i] *= proper;
    Y[i] *= proper;
  }
  SF_UNROLL
  for (int i = 0; i < 9; i += 4) {
    X[i] += SF_LIT(1.0) - proper;
    Y[i] += SF_LIT(1.0) - proper;
  }
  SF_UNROLL
  for (int step = 0; step < SF_POLAR_STEPS; ++step) {
    if (step > 0) sf_inverse_transpose3(X, Y);
    SF_REAL xx = SF_LIT(0.0);
    SF_REAL yy = SF_LIT(0.0);
    SF_UNROLL
    for (int i = 0; i < 9; ++i) {
      xx += X[i] * X[i];
      yy += Y[i] * Y[i];
    }
    SF_REAL g = SF_SQRT(SF_SQRT(yy / xx));
    SF_UNROLL
    for (int i = 0; i < 9; ++i) X[i] = SF_LIT(0.5) * (g * X[i] + Y[i] / g);
  }
  SF_UNROLL
  for (int r = 0; r < 3; ++r) {
    SF_UNROLL
    for (int k = 0; k < 3; ++k) frame[3 * r + k] = proper * X[3 * k + r] + (SF_LIT(1.0) - proper) * qr[3 * r + k];
  }
}

/* The element's frame by the scenario's rotation method: the polar frame when `polar` is
 * not 0 (material.rotation "polar"), else the QR frame. */
SF_FN void sf_element_rotation(SF_IN(grad, 12), SF_IN(p, 12), SF_REAL polar, SF_OUT(frame, 9)) {
  if (polar != SF_LIT(0.0)) {
    sf_element_polar_frame(grad, p, frame);
  } else {
    sf_element_frame(p, frame);
  }
}

/* y = R K_e R^T d with R = frame^T: the tangent stiffness product of one element, the cost
 * of every CG iteration (ARCHITECTURE.md: the element-iteration). */
SF_FN void sf_element_product(SF_IN(frame, 9), SF_IN(grad, 12), SF_REAL vlambda, SF_REAL vmu,
                              SF_IN(d, 12), SF_OUT(y, 12)) {
  SF_REAL G[9];
  sf_element_gradient(grad, d, SF_LIT(0.0), G);
  sf_element_stress_divergence(frame, grad, vlambda, vmu, G, SF_LIT(0.0), SF_LIT(1.0), y);
}

/* Elastic force on the four corners at positions p: f = -R K_e (R^T (p - p_0) - rest),
 * the corners' displacement measured in the element's current frame against its rest shape.
 * sum_c rest_c grad_c^T = I, so the rest shape enters as the identity subtracted from H. */
SF_FN void sf_element_force(SF_IN(frame, 9), SF_IN(grad, 12), SF_REAL vlambda, SF_REAL vmu,
                            SF_IN(p, 12), SF_OUT(f, 12)) {
  SF_REAL G[9];
  sf_element_gradient(grad, p, SF_LIT(1.0), G);
  sf_element_stress_divergence(frame, grad, vlambda, vmu, G, SF_LIT(1.0), SF_LIT(-1.0), f);
}

/* The diagonal of R K_e R^T (12 numbers), for the Jacobi preconditioner. The corner block
 * is K_cc = V ((lambda + mu) g g^T + mu |g|^2 I) in the rest frame; rotated, w = F^T g. */
SF_FN void sf_element_diagonal(SF_IN(frame, 9), SF_IN(grad, 12), SF_REAL vlambda, SF_REAL vmu,
                               SF_OUT(diag, 12)) {
  SF_UNROLL
  for (int c = 0; c < 4; ++c) {
    SF_REAL g0 = grad[3 * c];
    SF_REAL g1 = grad[3 * c + 1];
    SF_REAL g2 = grad[3 * c + 2];
    SF_REAL g_squared = g0 * g0 + g1 * g1 + g2 * g2;
    SF_UNROLL
    for (int k = 0; k < 3; ++k) {
      SF_REAL w = frame[k] * g0 + frame[3 + k] * g1 + frame[6 + k] * g2;
      diag[3 * c + k] = (vlambda + vmu) * w * w + vmu * g_squared;
    }
  }
}

#endif /* SIGMAFEM_ELEMENT_H */

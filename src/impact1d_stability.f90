!> RK4 on the scene's springs and dampers (docs/method.md, "Stability of the spring part"):
!> the linear part M x'' + C x' + K x = f has eigenvalues lambda (its modes); RK4 with step
!> h multiplies a mode by R(h lambda) = 1 + z + z^2/2 + z^3/6 + z^4/24 a step, so it is stable
!> only while |R(h lambda)| <= 1 for every mode (w h <= 2 sqrt 2 for an undamped spring,
!> c h / m <= 2.785 for a damper alone), and accurate only well inside that (a mode with
!> w h = 1 loses most of its amplitude in a few periods, silently). This module finds the
!> modes exactly (the eigenvalues of the first-order system), the largest stable step and
!> the error RK4 makes on the fastest mode.
module impact1d_stability
  use impact1d_kinds, only: wp, eps_wp
  implicit none
  private
  public :: linear_modes, stable_step, mode_error, coarse_rate, assemble

  !> Above this |lambda| h the fastest mode is stepped coarsely (a warning, with its error):
  !> RK4's error per step is |z|^5 / 120, so a mode of w h = 0.5 is off by ~1e-3 a period.
  real(wp), parameter :: coarse_rate = 0.5_wp
  !> Sweep of |z| along a ray: RK4's stability region lies within |z| < 3 (its boundary meets
  !> the real axis at -2.785 and the imaginary axis at 2.828).
  real(wp), parameter :: ray_step = 1.0e-3_wp, ray_end = 3.5_wp

contains

  !> The eigenvalues of the linear part of the motion of n bodies with mass matrix diag(mass),
  !> damping matrix c and stiffness matrix k: those of [[0, I], [-M^-1 K, -M^-1 C]], written
  !> for the state (x, v / s) with s the scale of sqrt(K / m), so that every entry is of the
  !> size of the eigenvalues and their rounding is relative to them.
  pure subroutine linear_modes(mass, c, k, lambda, ok)
    real(wp), intent(in) :: mass(:), c(:, :), k(:, :)
    complex(wp), intent(out) :: lambda(2 * size(mass))
    logical, intent(out) :: ok
    real(wp) :: a(2 * size(mass), 2 * size(mass)), s
    integer :: n, i
    n = size(mass)
    s = 0.0_wp
    do i = 1, n
      s = max(s, sqrt(maxval(abs(k(i, :))) / mass(i)))
    end do
    if (s == 0.0_wp) s = 1.0_wp
    a = 0.0_wp
    do i = 1, n
      a(i, n + i) = s
      a(n + i, 1:n) = -k(i, :) / (mass(i) * s)
      a(n + i, n + 1:) = -c(i, :) / mass(i)
    end do
    call eigenvalues(a, lambda, ok)
  end subroutine linear_modes

  !> The largest step RK4 is stable at for a mode lambda (huge for lambda = 0): where the ray
  !> from 0 towards lambda first leaves |R(z)| <= 1. A passive mode has Re lambda <= 0; a
  !> rounding-level positive real part (an undamped mode) is taken as zero.
  pure real(wp) function stable_step(lambda) result(h)
    complex(wp), intent(in) :: lambda
    complex(wp) :: u
    real(wp) :: lo, hi, mid
    integer :: j
    h = huge(1.0_wp)
    if (abs(lambda) == 0.0_wp) return
    u = cmplx(min(real(lambda, wp), 0.0_wp), aimag(lambda), wp) / abs(lambda)
    lo = 0.0_wp
    do j = 1, nint(ray_end / ray_step)
      hi = j * ray_step
      if (abs(growth(hi * u)) > 1.0_wp) exit
      lo = hi
    end do
    if (lo == hi) return
    do j = 1, 60
      mid = 0.5_wp * (lo + hi)
      if (abs(growth(mid * u)) > 1.0_wp) then
        hi = mid
      else
        lo = mid
      end if
    end do
    h = lo / abs(lambda)
  end function stable_step

  !> Relative error RK4 with step h makes on mode lambda over one of its periods (2 pi/|Im|)
  !> or, for a mode that only decays, over its time constant 1/|Re|: n steps of the per-step
  !> factor R(z) against the exact e^z.
  pure real(wp) function mode_error(lambda, h)
    complex(wp), intent(in) :: lambda
    real(wp), intent(in) :: h
    real(wp) :: n_steps
    complex(wp) :: z
    z = h * lambda
    if (abs(aimag(lambda)) > 0.0_wp) then
      n_steps = 2.0_wp * acos(-1.0_wp) / (abs(aimag(lambda)) * h)
    else
      n_steps = 1.0_wp / (abs(real(lambda, wp)) * h)
    end if
    mode_error = abs((growth(z) / exp(z))**n_steps - 1.0_wp)
  end function mode_error

  !> RK4's factor per step on y' = lambda y, z = h lambda.
  pure complex(wp) function growth(z)
    complex(wp), intent(in) :: z
    growth = 1.0_wp + z * (1.0_wp + z * (0.5_wp + z * (1.0_wp / 6.0_wp + z / 24.0_wp)))
  end function growth

  !> Eigenvalues of a small real matrix: Householder reduction to Hessenberg form, then the
  !> complex QR algorithm with Wilkinson shifts and deflation (Golub and Van Loan 7.5). ok is
  !> false if it did not converge (it does in a few iterations per eigenvalue).
  pure subroutine eigenvalues(a, lambda, ok)
    real(wp), intent(in) :: a(:, :)
    complex(wp), intent(out) :: lambda(size(a, 1))
    logical, intent(out) :: ok
    complex(wp) :: h(size(a, 1), size(a, 1))
    integer :: n, hi, l, iterations
    n = size(a, 1)
    h = hessenberg(a)
    hi = n
    iterations = 0
    ok = .true.
    do while (hi > 1)
      ! The active block is h(l:hi, l:hi): below l the subdiagonal is negligible.
      do l = hi, 2, -1
        if (abs(h(l, l - 1)) <= eps_wp * (abs(h(l, l)) + abs(h(l - 1, l - 1)))) exit
      end do
      if (l == hi) then
        lambda(hi) = h(hi, hi)
        hi = hi - 1
        iterations = 0
        cycle
      end if
      iterations = iterations + 1
      if (iterations > 100) then
        ok = .false.
        return
      end if
      call shifted_qr_step(h(l:hi, l:hi), wilkinson_shift(h(hi - 1:hi, hi - 1:hi), iterations))
    end do
    lambda(1) = h(1, 1)
  end subroutine eigenvalues

  !> Hessenberg form of a (same eigenvalues) by Householder reflections.
  pure function hessenberg(a) result(h)
    real(wp), intent(in) :: a(:, :)
    complex(wp) :: h(size(a, 1), size(a, 1))
    real(wp) :: r(size(a, 1), size(a, 1)), u(size(a, 1)), alpha
    integer :: n, k
    n = size(a, 1)
    r = a
    do k = 1, n - 2
      u(k + 1:) = r(k + 1:, k)
      if (norm2(u(k + 2:)) == 0.0_wp) cycle
      alpha = -sign(norm2(u(k + 1:)), u(k + 1))
      u(k + 1) = u(k + 1) - alpha
      u(k + 1:) = u(k + 1:) / norm2(u(k + 1:))
      r(k + 1:, :) = r(k + 1:, :) - 2.0_wp * spread(u(k + 1:), 2, n) * spread(matmul(u(k + 1:), r(k + 1:, :)), 1, n - k)
      r(:, k + 1:) = r(:, k + 1:) - 2.0_wp * spread(matmul(r(:, k + 1:), u(k + 1:)), 2, n - k) * spread(u(k + 1:), 1, n)
    end do
    h = r
  end function hessenberg

  !> The eigenvalue of the trailing 2x2 block nearer its last diagonal entry; every tenth
  !> iteration an exceptional shift breaks a cycle.
  pure complex(wp) function wilkinson_shift(b, iterations) result(mu)
    complex(wp), intent(in) :: b(2, 2)
    integer, intent(in) :: iterations
    complex(wp) :: mean, root
    mean = 0.5_wp * (b(1, 1) + b(2, 2))
    root = sqrt((0.5_wp * (b(1, 1) - b(2, 2)))**2 + b(1, 2) * b(2, 1))
    mu = mean + root
    if (abs(mean - root - b(2, 2)) < abs(mu - b(2, 2))) mu = mean - root
    if (mod(iterations, 10) == 0) mu = mu + abs(b(2, 1))
  end function wilkinson_shift

  !> One QR step on an unreduced Hessenberg block: h - mu = QR (Givens), h <- RQ + mu.
  pure subroutine shifted_qr_step(h, mu)
    complex(wp), intent(inout) :: h(:, :)
    complex(wp), intent(in) :: mu
    complex(wp) :: c(size(h, 1)), s(size(h, 1)), row(size(h, 1)), col(size(h, 1))
    real(wp) :: r
    integer :: n, j
    n = size(h, 1)
    do j = 1, n
      h(j, j) = h(j, j) - mu
    end do
    do j = 1, n - 1
      r = hypot(abs(h(j, j)), abs(h(j + 1, j)))
      c(j) = 1.0_wp
      s(j) = 0.0_wp
      if (r > 0.0_wp) then
        c(j) = h(j, j) / r
        s(j) = h(j + 1, j) / r
      end if
      row = h(j, :)
      h(j, :) = conjg(c(j)) * row + conjg(s(j)) * h(j + 1, :)
      h(j + 1, :) = -s(j) * row + c(j) * h(j + 1, :)
    end do
    do j = 1, n - 1
      col = h(:, j)
      h(:, j) = col * c(j) + h(:, j + 1) * s(j)
      h(:, j + 1) = -col * conjg(s(j)) + h(:, j + 1) * conjg(c(j))
    end do
    do j = 1, n
      h(j, j) = h(j, j) + mu
    end do
  end subroutine shifted_qr_step

  !> The matrix of the elements' coefficients: each adds its coefficient to its bodies'
  !> diagonal entries and takes it from their shared off-diagonal ones, in record order.
  !> (An off-diagonal entry is set, not summed from +0: a link of coefficient 0 gives -0 there,
  !> as the matrix written out for the tutorial's elements did.)
  !> Elements given by their ends body(:, j) (0 the ground) and coefficients (the element
  !> records, and the compliant stops' rows as if engaged: build_scene's check_step).
  pure subroutine assemble(body, coefficient, matrix)
    integer, intent(in) :: body(:, :)
    real(wp), intent(in) :: coefficient(:)
    real(wp), intent(out) :: matrix(:, :)
    integer :: j
    logical :: coupled(size(matrix, 1), size(matrix, 1))
    matrix = 0.0_wp
    coupled = .false.
    do j = 1, size(coefficient)
      associate (a => body(1, j), b => body(2, j))
        matrix(b, b) = matrix(b, b) + coefficient(j)
        if (a == 0) cycle
        matrix(a, a) = matrix(a, a) + coefficient(j)
        if (coupled(a, b)) then
          matrix(a, b) = matrix(b, a) - coefficient(j)
        else
          matrix(a, b) = -coefficient(j)
        end if
        matrix(b, a) = matrix(a, b)
        coupled(a, b) = .true.
        coupled(b, a) = .true.
      end associate
    end do
  end subroutine assemble
end module impact1d_stability

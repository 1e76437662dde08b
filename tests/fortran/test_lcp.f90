!> The LCP solver (impact1d_lcp): random P-matrix problems against the unique solution found
!> by enumerating every complementary basis, random positive semidefinite (convex QP, and
!> box-friction-like with a skew part) problems checked for complementarity, and the
!> degenerate cases: ties, zero right-hand sides, a rank-one matrix, the rate dq deciding,
!> a ray, a problem larger than the work.
program test_lcp
  use impact1d_kinds, only: wp
  use impact1d_lcp, only: lcp_work_type, lcp_reserve, lcp_solve, lcp_basis_values, &
    lcp_solved, lcp_ray, lcp_too_large
  use testing, only: check, finish, seed_random
  implicit none
  integer, parameter :: cap = 16
  type(lcp_work_type) :: work
  real(wp) :: m(cap, cap), q(cap), dq(cap), z(cap), w(cap), zb(cap), worst
  integer :: status, trial, n, i, fails

  call seed_random(7919, 17)
  call lcp_reserve(work, cap)

  ! P-matrices (positive definite, symmetric or not): the solution is unique.
  worst = 0.0_wp
  fails = 0
  do trial = 1, 2000
    n = 1 + mod(trial, 8)
    call random_pd(m, n, symmetric=mod(trial, 2) == 0)
    call random_number(q(1:n))
    q(1:n) = 2.0_wp * q(1:n) - 1.0_wp
    call lcp_solve(work, m(1:n, 1:n), q(1:n), z, w, status)
    call enumerate(m, q, n, zb)
    if (status /= lcp_solved) fails = fails + 1
    worst = max(worst, complementarity(m, q, z, w, n), &
      maxval(abs(z(1:n) - zb(1:n))) / (1.0_wp + maxval(abs(zb(1:n)))))
  end do
  print '(a, es10.3)', 'P-matrix problems: worst relative error ', worst
  call check(fails == 0, 'P-matrix problems: every one solved')
  call check(worst < 1.0e-13_wp, 'P-matrix problems: the unique solution to 1e-13')

  ! Positive semidefinite, singular (rank < n), feasible by construction; and the box
  ! friction shape [[S, D], [-D, 0]] (skew off-diagonal blocks), as the mode solve has.
  worst = 0.0_wp
  fails = 0
  do trial = 1, 2000
    n = 2 + mod(trial, 12)
    if (mod(trial, 2) == 0) then
      call random_psd(m, n)
    else
      call random_box(m, n)
    end if
    call random_feasible_q(m, n, q)
    call lcp_solve(work, m(1:n, 1:n), q(1:n), z, w, status)
    if (status /= lcp_solved) fails = fails + 1
    worst = max(worst, complementarity(m, q, z, w, n))
  end do
  print '(a, es10.3)', 'PSD problems: worst relative complementarity ', worst
  call check(fails == 0, 'PSD problems: every one solved (Lemke ends with a solution)')
  call check(worst < 1.0e-13_wp, 'PSD problems: complementary to 1e-13')

  call degenerate_cases()
  call finish('test_lcp')

contains

  !> Ties: a rank-one matrix with equal q (the lowest row binds), exact zeros in q (no
  !> pivot), the rate deciding a zero q, a ray, and a problem too large for the work.
  subroutine degenerate_cases()
    n = 4
    m(1:n, 1:n) = 1.0_wp
    q(1:n) = -1.0_wp
    call lcp_solve(work, m(1:n, 1:n), q(1:n), z, w, status)
    call check(status == lcp_solved .and. z(1) == 1.0_wp .and. all(z(2:n) == 0.0_wp) .and. all(w(1:n) == 0.0_wp), &
      'all rows tied (rank one, equal q): the lowest row binds, z = e_1')
    call check(complementarity(m, q, z, w, n) == 0.0_wp, 'rank-one tie: exact')
    q(1:n) = [0.0_wp, -1.0_wp, 0.0_wp, -1.0_wp]
    call lcp_solve(work, m(1:n, 1:n), q(1:n), z, w, status)
    call check(status == lcp_solved .and. complementarity(m, q, z, w, n) < 1.0e-15_wp .and. sum(z(1:n)) == 1.0_wp, &
      'rank one with zero and tied q: solved, sum z = 1')
    q(1:n) = 0.0_wp
    call lcp_solve(work, m(1:n, 1:n), q(1:n), z, w, status)
    call check(status == lcp_solved .and. work%pivots == 0 .and. all(z(1:n) == 0.0_wp), 'q = 0: z = 0, no pivot')

    ! q = 0 going negative (dq = -1): the basis of the coming instant has z basic, z' = 1.
    m(1, 1) = 2.0_wp
    call lcp_solve(work, m(1:1, 1:1), [0.0_wp], z, w, status, dq=[-1.0_wp])
    call lcp_basis_values(work, [-1.0_wp], zb, w)
    call check(status == lcp_solved .and. z(1) == 0.0_wp .and. zb(1) == 0.5_wp, &
      'q = 0 with a negative rate: z enters, rate 1/2')
    call lcp_solve(work, m(1:1, 1:1), [0.0_wp], z, w, status, dq=[1.0_wp])
    call lcp_basis_values(work, [1.0_wp], zb, w)
    call check(status == lcp_solved .and. zb(1) == 0.0_wp .and. w(1) == 1.0_wp, &
      'q = 0 with a positive rate: w stays basic, rate 1')

    ! w = -z - 1 >= 0 has no solution: a ray, reported, not a stop.
    call lcp_solve(work, reshape([-1.0_wp], [1, 1]), [-1.0_wp], z, w, status)
    call check(status == lcp_ray, 'infeasible LCP: ray termination reported')
    call lcp_solve(work, m(1:cap, 1:cap), [(-1.0_wp, i = 1, cap)], z, w, status)
    call check(status /= lcp_too_large, 'a problem of the reserved size is taken')
    block
      real(wp) :: big(cap + 1, cap + 1), zz(cap + 1), ww(cap + 1)
      big = 0.0_wp
      call lcp_solve(work, big, [(-1.0_wp, i = 1, cap + 1)], zz, ww, status)
      call check(status == lcp_too_large, 'a problem beyond the reserved size is refused')
    end block
  end subroutine degenerate_cases

  !> Worst violation, relative to the data's size: z < 0, w < 0, w - (M z + q), min(z, w)
  !> (z in units of q / M).
  real(wp) function complementarity(m, q, z, w, n) result(worst)
    real(wp), intent(in) :: m(:, :), q(:), z(:), w(:)
    integer, intent(in) :: n
    real(wp) :: scale, msize
    integer :: j
    msize = maxval(abs(m(1:n, 1:n)))
    scale = maxval(abs(q(1:n))) + msize * maxval(abs(z(1:n)))
    worst = 0.0_wp
    do j = 1, n
      worst = max(worst, -z(j) * msize / scale, -w(j) / scale, &
        abs(w(j) - (dot_product(m(j, 1:n), z(1:n)) + q(j))) / scale, &
        min(abs(z(j)) * msize, abs(w(j))) / scale)
    end do
  end function complementarity

  !> S + K: S = A A^T + I/10 (A uniform in [-1, 1]), K skew unless symmetric.
  subroutine random_pd(m, n, symmetric)
    real(wp), intent(out) :: m(:, :)
    integer, intent(in) :: n
    logical, intent(in) :: symmetric
    real(wp) :: a(cap, cap)
    integer :: i
    call random_number(a(1:n, 1:n))
    a(1:n, 1:n) = 2.0_wp * a(1:n, 1:n) - 1.0_wp
    m(1:n, 1:n) = matmul(a(1:n, 1:n), transpose(a(1:n, 1:n)))
    do i = 1, n
      m(i, i) = m(i, i) + 0.1_wp
    end do
    if (.not. symmetric) then
      call random_number(a(1:n, 1:n))
      m(1:n, 1:n) = m(1:n, 1:n) + (a(1:n, 1:n) - transpose(a(1:n, 1:n)))
    end if
  end subroutine random_pd

  !> A A^T with A of n x (n/2) (rank n/2 < n), with identical and opposite rows.
  subroutine random_psd(m, n)
    real(wp), intent(out) :: m(:, :)
    integer, intent(in) :: n
    real(wp) :: a(cap, cap)
    integer :: k
    k = max(1, n / 2)
    call random_number(a(1:n, 1:k))
    a(1:n, 1:k) = 2.0_wp * a(1:n, 1:k) - 1.0_wp
    if (n > 2) a(n, 1:k) = a(1, 1:k)       ! two identical contact rows
    if (n > 3) a(n - 1, 1:k) = -a(2, 1:k)  ! two opposite ones (a rigid link's two limits)
    m(1:n, 1:n) = matmul(a(1:n, 1:k), transpose(a(1:n, 1:k)))
  end subroutine random_psd

  !> The friction-box shape: [[S, D], [-D, 0]], S PSD of size n - n/2, D diagonal > 0.
  subroutine random_box(m, n)
    real(wp), intent(out) :: m(:, :)
    integer, intent(in) :: n
    integer :: h, i
    real(wp) :: d
    h = n / 2
    call random_psd(m, n - h)
    m(1:n, n - h + 1:n) = 0.0_wp
    m(n - h + 1:n, 1:n) = 0.0_wp
    do i = 1, h
      call random_number(d)
      m(i, n - h + i) = 0.5_wp + d
      m(n - h + i, i) = -(0.5_wp + d)
    end do
  end subroutine random_box

  !> q = w0 - M z0 with z0, w0 >= 0 (half of each zero): the LCP is feasible.
  subroutine random_feasible_q(m, n, q)
    real(wp), intent(in) :: m(:, :)
    integer, intent(in) :: n
    real(wp), intent(out) :: q(:)
    real(wp) :: z0(cap), w0(cap), u(cap)
    call random_number(z0(1:n))
    call random_number(w0(1:n))
    call random_number(u(1:n))
    where (u(1:n) < 0.5_wp) z0(1:n) = 0.0_wp
    where (u(1:n) >= 0.5_wp) w0(1:n) = 0.0_wp
    q(1:n) = w0(1:n) - matmul(m(1:n, 1:n), z0(1:n))
  end subroutine random_feasible_q

  !> The solution of a P-matrix LCP found by trying every complementary basis.
  subroutine enumerate(m, q, n, z)
    real(wp), intent(in) :: m(:, :), q(:)
    integer, intent(in) :: n
    real(wp), intent(out) :: z(:)
    real(wp) :: a(cap, cap), b(cap), w(cap)
    integer :: mask, j
    logical :: in_s(cap)
    do mask = 0, 2**n - 1
      in_s(1:n) = [(btest(mask, j - 1), j = 1, n)]
      ! Columns: z_j for j in S, w_j otherwise; solve (-M_S | I) x = q.
      do j = 1, n
        if (in_s(j)) then
          a(1:n, j) = -m(1:n, j)
        else
          a(1:n, j) = 0.0_wp
          a(j, j) = 1.0_wp
        end if
      end do
      b(1:n) = q(1:n)
      call gauss(a, b, n)
      if (any(b(1:n) < -1.0e-12_wp)) cycle
      z(1:n) = merge(b(1:n), 0.0_wp, in_s(1:n))
      w(1:n) = matmul(m(1:n, 1:n), z(1:n)) + q(1:n)
      if (all(w(1:n) >= -1.0e-12_wp)) return
    end do
    z(1:n) = huge(1.0_wp)
  end subroutine enumerate

  !> Solve a x = b by Gaussian elimination with partial pivoting (b overwritten).
  subroutine gauss(a, b, n)
    real(wp), intent(inout) :: a(:, :), b(:)
    integer, intent(in) :: n
    integer :: k, p, j
    real(wp) :: row(cap), tmp
    do k = 1, n
      p = k - 1 + maxloc(abs(a(k:n, k)), dim=1)
      row(1:n) = a(k, 1:n)
      a(k, 1:n) = a(p, 1:n)
      a(p, 1:n) = row(1:n)
      tmp = b(k)
      b(k) = b(p)
      b(p) = tmp
      do j = k + 1, n
        tmp = a(j, k) / a(k, k)
        a(j, k:n) = a(j, k:n) - tmp * a(k, k:n)
        b(j) = b(j) - tmp * b(k)
      end do
    end do
    do k = n, 1, -1
      b(k) = (b(k) - dot_product(a(k, k + 1:n), b(k + 1:n))) / a(k, k)
    end do
  end subroutine gauss
end program test_lcp

!> A pivoting solver of the linear complementarity problem (LCP)
!>     w = M z + q,   w >= 0,   z >= 0,   w . z = 0
!> by Lemke's complementary pivoting (covering vector d = 1, artificial variable z0) with the
!> lexicographic ratio test, the kernel of the N-body mode solve and joint impact (issue 19,
!> stages 4 and 5; docs/method.md, "N bodies: the cluster's mode solve").
!>
!> What it guarantees:
!> - It ends: the lexicographic rule never revisits a basis, so degenerate problems (many
!>   zero forces, dependent contact rows) do not cycle. The pivots are bounded (max_pivots).
!> - status = lcp_solved: z, w solve the LCP to rounding (w is M z + q recomputed from the
!>   original data, z >= 0, and each pair has one member at rounding level). Lemke finds a
!>   solution whenever M is copositive-plus (a P-matrix, or positive semidefinite as the
!>   LCPs of convex quadratic programs are) and the LCP is feasible; otherwise it may end
!>   on a ray: status = lcp_ray (no solution was found; z = 0, w = q), never a stop.
!> - Ties are decided in a fixed order: the problem solved is the lexicographically
!>   perturbed one, q + eps dq + (eps^2 on row n, ..., eps^(n+1) on row 1): first the rate
!>   dq (the mode that holds just AFTER an instant, when dq is the right derivative of q),
!>   then, rows tied in q and dq, the lowest-numbered row is the most binding one. Within a
!>   tolerance of rounding (rel_tol of the data) two values count as equal.
!> - No allocation while solving: the caller sizes an lcp_work_type once (lcp_reserve) and
!>   passes it to every solve; a problem larger than the reservation is refused
!>   (lcp_too_large).
!> After a solve, the final basis is kept factored: lcp_basis_values gives the basis's z
!> and w for another right-hand side (the rates of a mode's forces, its hold conditions).
module impact1d_lcp
  use impact1d_kinds, only: wp, eps_wp
  implicit none
  private
  public :: lcp_work_type, lcp_reserve, lcp_solve, lcp_basis_values
  public :: lcp_solved, lcp_ray, lcp_max_pivots, lcp_too_large, lcp_singular

  integer, parameter :: lcp_solved = 0      !< z, w solve the LCP
  integer, parameter :: lcp_ray = 1         !< secondary ray: no solution found (M not copositive-plus, or infeasible)
  integer, parameter :: lcp_max_pivots = 2  !< the pivot budget ran out
  integer, parameter :: lcp_too_large = 3   !< n exceeds the work's reservation
  integer, parameter :: lcp_singular = 4    !< the final basis is numerically singular

  !> Relative size of a value that is zero: entries of the data, rounded through the pivots.
  real(wp), parameter :: rel_tol = 1.0e3_wp * eps_wp

  !> The solver's memory, owned by the caller and sized once by lcp_reserve.
  type :: lcp_work_type
    integer :: capacity = 0                 !< largest n a solve may have
    integer :: n = 0                        !< size of the last solve
    integer :: pivots = 0                   !< pivots the last solve took
    !> (capacity, 2 capacity + 3) tableau B^-1 [I, -M, -d, q, dq]: columns w_1..w_n,
    !> z_1..z_n, z0, then the two right-hand sides (for size n: columns 1..2n+3)
    real(wp), allocatable :: table(:, :)
    real(wp), allocatable :: lu(:, :)       !< (capacity, capacity) the final basis's LU factors
    real(wp), allocatable :: column(:)      !< (capacity) the entering column during a pivot
    integer, allocatable :: basic(:)        !< (capacity) variable basic in row i: j = w_j, n + j = z_j, 2n + 1 = z0
    integer, allocatable :: perm(:)         !< (capacity) LU's row interchanges
    !> zero levels of the two right-hand sides' entries: in q's units (rows with a basic w or
    !> z0) and in z's (rows with a basic z, of the size q / M)
    real(wp) :: tol_q = 0.0_wp, tol_dq = 0.0_wp, m_size = 1.0_wp
  end type lcp_work_type

contains

  !> Size the work for problems of up to capacity unknowns (call once, outside any step loop).
  subroutine lcp_reserve(work, capacity)
    type(lcp_work_type), intent(inout) :: work
    integer, intent(in) :: capacity
    if (work%capacity >= capacity .and. allocated(work%table)) return
    if (allocated(work%table)) deallocate(work%table, work%lu, work%column, work%basic, work%perm)
    allocate(work%table(capacity, 2 * capacity + 3), work%lu(capacity, capacity), &
      work%column(capacity), work%basic(capacity), work%perm(capacity))
    work%capacity = capacity
  end subroutine lcp_reserve

  !> Solve w = m z + q, w, z >= 0, w.z = 0 for n = size(q) (module header). dq: the rate of
  !> q (ties are decided by where q is going; 0 when absent). max_pivots: budget (default
  !> 50 (n + 1)). z, w: size >= n, the solution in 1..n.
  subroutine lcp_solve(work, m, q, z, w, status, dq, max_pivots)
    type(lcp_work_type), intent(inout) :: work
    real(wp), intent(in) :: m(:, :), q(:)
    real(wp), intent(out) :: z(:), w(:)
    integer, intent(out) :: status
    real(wp), intent(in), optional :: dq(:)
    integer, intent(in), optional :: max_pivots
    integer :: n, budget, row, entering, leaving
    n = size(q)
    z(1:n) = 0.0_wp
    w(1:n) = q
    work%n = n
    work%pivots = 0
    status = lcp_too_large
    if (n > work%capacity) return
    budget = 50 * (n + 1)
    if (present(max_pivots)) budget = max_pivots
    status = lcp_solved
    if (n == 0) return
    call load_tableau(work, n, m, q, dq)
    ! Basis of the w's is lexicographically feasible: z = 0 (the basis is I, factored).
    row = leaving_row(work, n, 2 * n + 1, .true.)
    if (lex_positive(work, n, row)) then
      call factor_basis(work, n, m, status)
      return
    end if
    entering = 2 * n + 1
    do while (work%pivots < budget)
      call pivot(work, n, row, entering, leaving)
      if (leaving == 2 * n + 1) then
        call factor_basis(work, n, m, status)
        if (status == lcp_solved) call basis_solution(work, n, m, q, z, w)
        return
      end if
      ! The complement of the variable that left enters.
      entering = leaving + n
      if (leaving > n) entering = leaving - n
      row = leaving_row(work, n, entering, .false.)
      if (row == 0) then
        status = lcp_ray
        return
      end if
    end do
    status = lcp_max_pivots
  end subroutine lcp_solve

  !> The tableau [I, -M, -1, q, dq] with the w's basic, and the zero levels of q and dq.
  subroutine load_tableau(work, n, m, q, dq)
    type(lcp_work_type), intent(inout) :: work
    integer, intent(in) :: n
    real(wp), intent(in) :: m(:, :), q(:)
    real(wp), intent(in), optional :: dq(:)
    integer :: j
    associate (t => work%table)
      t(1:n, 1:n) = 0.0_wp
      do j = 1, n
        t(j, j) = 1.0_wp
        work%basic(j) = j
      end do
      t(1:n, n + 1:2 * n) = -m(1:n, 1:n)
      t(1:n, 2 * n + 1) = -1.0_wp
      t(1:n, 2 * n + 2) = q(1:n)
      t(1:n, 2 * n + 3) = 0.0_wp
      if (present(dq)) t(1:n, 2 * n + 3) = dq(1:n)
      ! Rounding through the pivots grows with the data's size: q's own, and M times a z of
      ! the size q / M makes, which is again of q's size.
      work%tol_q = rel_tol * maxval(abs(t(1:n, 2 * n + 2))) + tiny(1.0_wp)
      work%tol_dq = rel_tol * maxval(abs(t(1:n, 2 * n + 3))) + tiny(1.0_wp)
      work%m_size = maxval(abs(m(1:n, 1:n)))
      if (work%m_size == 0.0_wp) work%m_size = 1.0_wp
    end associate
  end subroutine load_tableau

  !> The row whose basic variable leaves when column e enters: the lexicographic minimum of
  !> (rhs, drhs, B^-1 row in the order n..1) / t(i, e) over t(i, e) > 0 (first: over all
  !> rows with divisor 1, z0 entering against d = 1), lowest row on exact ties; 0 if none.
  integer function leaving_row(work, n, e, first) result(best)
    type(lcp_work_type), intent(in) :: work
    integer, intent(in) :: n, e
    logical, intent(in) :: first
    integer :: i
    real(wp) :: col_tol, divisor, best_divisor
    !> Each row's largest |B^-1| entry, found when a tie first needs it (-1: not yet): the
    !> ties of a degenerate problem (a train at rest) compared them again for every pair, a
    !> strided pass over the row each time, most of a solve's time.
    real(wp) :: row_size(n)
    row_size = -1.0_wp
    best = 0
    best_divisor = 1.0_wp
    col_tol = rel_tol * maxval(abs(work%table(1:n, e)))
    do i = 1, n
      divisor = 1.0_wp
      if (.not. first) then
        divisor = work%table(i, e)
        if (divisor <= col_tol) cycle
      end if
      if (best == 0) then
        best = i
        best_divisor = divisor
      else if (lex_less(work, n, i, divisor, best, best_divisor, row_size)) then
        best = i
        best_divisor = divisor
      end if
    end do
  end function leaving_row

  !> Row i's key divided by di below row j's divided by dj (equal within the zero levels);
  !> row_size: the rows' largest |B^-1| entries, filled where still -1.
  logical function lex_less(work, n, i, di, j, dj, row_size)
    type(lcp_work_type), intent(in) :: work
    integer, intent(in) :: n, i, j
    real(wp), intent(in) :: di, dj
    real(wp), intent(inout) :: row_size(:)
    real(wp) :: x, y, tol
    integer :: c
    associate (t => work%table)
      do c = 2 * n + 2, 2 * n + 3
        x = t(i, c) / di
        y = t(j, c) / dj
        if (abs(x - y) > zero_level(work, n, i, c) / di + zero_level(work, n, j, c) / dj) then
          lex_less = x < y
          return
        end if
      end do
      ! B^-1's entries: equal within rounding of the rows' sizes (an exact zero against a
      ! rounded one is a tie, not a decision by noise).
      if (row_size(i) < 0.0_wp) row_size(i) = maxval(abs(t(i, 1:n)))
      if (row_size(j) < 0.0_wp) row_size(j) = maxval(abs(t(j, 1:n)))
      tol = rel_tol * (row_size(i) / di + row_size(j) / dj)
      do c = n, 1, -1
        ! (two zeros are equal at any tolerance: no divisions for them)
        if (t(i, c) == 0.0_wp .and. t(j, c) == 0.0_wp) cycle
        x = t(i, c) / di
        y = t(j, c) / dj
        if (abs(x - y) > tol) then
          lex_less = x < y
          return
        end if
      end do
    end associate
    lex_less = .false.
  end function lex_less

  !> Whether row i's key (rhs, drhs, B^-1 row) is lexicographically >= 0 for every row i,
  !> given the minimum row (so only that row is tested).
  logical function lex_positive(work, n, row)
    type(lcp_work_type), intent(in) :: work
    integer, intent(in) :: n, row
    integer :: c
    associate (t => work%table)
      lex_positive = .true.
      if (abs(t(row, 2 * n + 2)) > zero_level(work, n, row, 2 * n + 2)) then
        lex_positive = t(row, 2 * n + 2) > 0.0_wp
      else if (abs(t(row, 2 * n + 3)) > zero_level(work, n, row, 2 * n + 3)) then
        lex_positive = t(row, 2 * n + 3) > 0.0_wp
      else
        do c = n, 1, -1
          if (t(row, c) /= 0.0_wp) then
            lex_positive = t(row, c) > 0.0_wp
            return
          end if
        end do
      end if
    end associate
  end function lex_positive

  !> Rounding level of tableau entry (i, c), c one of the right-hand sides: in the units of
  !> row i's basic variable.
  pure real(wp) function zero_level(work, n, i, c)
    type(lcp_work_type), intent(in) :: work
    integer, intent(in) :: n, i, c
    zero_level = work%tol_q
    if (c == 2 * n + 3) zero_level = work%tol_dq
    if (work%basic(i) > n .and. work%basic(i) <= 2 * n) zero_level = zero_level / work%m_size
  end function zero_level

  !> Gauss-Jordan pivot on (row, e): variable e becomes basic in row; leaving is the one
  !> that was.
  subroutine pivot(work, n, row, e, leaving)
    type(lcp_work_type), intent(inout) :: work
    integer, intent(in) :: n, row, e
    integer, intent(out) :: leaving
    integer :: c, i
    real(wp) :: p, t_rc
    associate (t => work%table, col => work%column)
      p = t(row, e)
      col(1:n) = t(1:n, e)
      do c = 1, 2 * n + 3
        if (t(row, c) == 0.0_wp) cycle
        t_rc = t(row, c) / p
        t(row, c) = t_rc
        do i = 1, n
          if (i /= row) t(i, c) = t(i, c) - col(i) * t_rc
        end do
      end do
      ! The entering column is exactly a unit vector.
      t(1:n, e) = 0.0_wp
      t(row, e) = 1.0_wp
    end associate
    leaving = work%basic(row)
    work%basic(row) = e
    work%pivots = work%pivots + 1
  end subroutine pivot

  !> LU factors (partial pivoting) of the final basis from the original data: columns e_j
  !> for a basic w_j, -M(:, j) for a basic z_j, -1 for z0.
  subroutine factor_basis(work, n, m, status)
    type(lcp_work_type), intent(inout) :: work
    integer, intent(in) :: n
    real(wp), intent(in) :: m(:, :)
    integer, intent(out) :: status
    integer :: i, j, k, p
    real(wp) :: big
    associate (a => work%lu)
      do i = 1, n
        j = work%basic(i)
        a(1:n, i) = 0.0_wp
        if (j <= n) then
          a(j, i) = 1.0_wp
        else if (j <= 2 * n) then
          a(1:n, i) = -m(1:n, j - n)
        else
          a(1:n, i) = -1.0_wp
        end if
      end do
      big = maxval(abs(a(1:n, 1:n)))
      status = lcp_solved
      do k = 1, n
        p = k - 1 + maxloc(abs(a(k:n, k)), dim=1)
        work%perm(k) = p
        if (abs(a(p, k)) <= eps_wp * big) then
          status = lcp_singular
          return
        end if
        if (p /= k) call swap_rows(a, n, k, p)
        a(k + 1:n, k) = a(k + 1:n, k) / a(k, k)
        do j = k + 1, n
          a(k + 1:n, j) = a(k + 1:n, j) - a(k + 1:n, k) * a(k, j)
        end do
      end do
    end associate
  end subroutine factor_basis

  pure subroutine swap_rows(a, n, k, p)
    real(wp), intent(inout) :: a(:, :)
    integer, intent(in) :: n, k, p
    integer :: j
    real(wp) :: tmp
    do j = 1, n
      tmp = a(k, j)
      a(k, j) = a(p, j)
      a(p, j) = tmp
    end do
  end subroutine swap_rows

  !> The basic values x = B^-1 rhs through the LU factors (overwrites rhs with x).
  pure subroutine lu_solve(lu, perm, n, rhs)
    real(wp), intent(in) :: lu(:, :)
    integer, intent(in) :: perm(:)
    integer, intent(in) :: n
    real(wp), intent(inout) :: rhs(:)
    integer :: k, p
    real(wp) :: tmp
    ! The row interchanges first: factor_basis swapped whole rows, L's columns included.
    do k = 1, n
      p = perm(k)
      if (p /= k) then
        tmp = rhs(k)
        rhs(k) = rhs(p)
        rhs(p) = tmp
      end if
    end do
    do k = 1, n
      rhs(k + 1:n) = rhs(k + 1:n) - lu(k + 1:n, k) * rhs(k)
    end do
    do k = n, 1, -1
      rhs(k) = rhs(k) / lu(k, k)
      rhs(1:k - 1) = rhs(1:k - 1) - lu(1:k - 1, k) * rhs(k)
    end do
  end subroutine lu_solve

  !> The solution of the final basis, recomputed from the original data: z from the basis
  !> (a basic z at rounding level below zero is zero), then w = M z + q.
  subroutine basis_solution(work, n, m, q, z, w)
    type(lcp_work_type), intent(inout) :: work
    integer, intent(in) :: n
    real(wp), intent(in) :: m(:, :), q(:)
    real(wp), intent(inout) :: z(:), w(:)
    integer :: j
    call lcp_basis_values(work, q, z, w)
    z(1:n) = max(z(1:n), 0.0_wp)
    do j = 1, n
      w(j) = q(j)
    end do
    do j = 1, n
      if (z(j) /= 0.0_wp) w(1:n) = w(1:n) + m(1:n, j) * z(j)
    end do
  end subroutine basis_solution

  !> The last solve's basis applied to another right-hand side r (size n): z and w of the
  !> basic variables (the others 0), linear in r. For r = dq they are the solution's rates.
  subroutine lcp_basis_values(work, r, z, w)
    type(lcp_work_type), intent(inout) :: work
    real(wp), intent(in) :: r(:)
    real(wp), intent(out) :: z(:), w(:)
    integer :: i, j, n
    n = work%n
    z(1:n) = 0.0_wp
    w(1:n) = 0.0_wp
    work%column(1:n) = r(1:n)
    call lu_solve(work%lu, work%perm, n, work%column)
    do i = 1, n
      j = work%basic(i)
      if (j <= n) then
        w(j) = work%column(i)
      else if (j <= 2 * n) then
        z(j - n) = work%column(i)
      end if
    end do
  end subroutine lcp_basis_values
end module impact1d_lcp

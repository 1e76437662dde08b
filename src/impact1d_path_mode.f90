!> The mode of a cluster whose rows form a path (issue 20 item 3; docs/method.md section 9,
!> "Clusters along a path"): the same mode as impact1d_cluster_mode's dense LCP followed by
!> impact1d_body_mode's preference for friction, in O(n) per solve instead of a dense LCP of
!> rows + 2 n unknowns.
!>
!> Which clusters: each body in at most two candidate rows, the body-body rows of the form
!> (-1, 1) or (1, -1) joining the bodies in a path p_1 .. p_n, at most one wall, on an end
!> body, and every row ordering the path the same way (s = +1 or -1 on the row's later
!> body): with u_t = s a(p_t) the rows say 0 <= u_1 (the wall, put first) and u_1 <= u_2 <=
!> .. <= u_n. The row matrix J M^-1 J^T is then a tridiagonal Z-matrix (a Stieltjes matrix);
!> a train standing buffer to buffer, or pulled along by taut couplers, is one.
!>
!> The method. The accelerations minimise sum_t f_t(u_t), f_t(u) = m u^2 / 2 - b u + beta |u|
!> (b the applied force and sliding friction, beta the bound of a body at rest) subject to
!> the order: a separable convex problem on a total order, solved exactly by pooling adjacent
!> violators (each block at the minimiser of its summed f: the soft threshold of its summed b
!> by its summed beta over its mass; the wall a block held at 0). Ties are decided by the
!> rate as the dense solve's lexicographic Lemke does: every value is a pair (value, rate)
!> compared lexicographically, the problem solved being b + eps db. Static above sliding as
!> impact1d_cluster_mode: beta = s for every body at rest, those that move break away to
!> beta = c, solved again until none does.
!> The contact forces are unique where the bodies move; along a run of stuck bodies they are
!> not (friction may carry what a row carries). impact1d_body_mode then prefers friction:
!> it lets go a held row whose force friction alone can carry while the row's ends stay
!> otherwise joined, which leaves held the rows whose force is positive in the least force
!> distribution and, of the force-free closed rows, all but one on each cycle through the
!> ground (hold_path_rows). That distribution is the least solution of the difference
!> constraints lambda_t - lambda_(t-1) in [L_t, U_t], lambda >= 0: two sweeps. A body with
!> static but no sliding friction that breaks away slides the way it leaves, as in
!> impact1d_cluster_mode's mode_of.
!> No allocation: path_reserve sizes the work once.
module impact1d_path_mode
  use impact1d_kinds, only: wp, eps_wp
  use impact1d_clusters, only: row_closed
  implicit none
  private
  public :: path_work_type, path_reserve, path_order, path_walk, path_mode

  !> Relative size of a zero force (impact1d_cluster_mode's).
  real(wp), parameter :: rel_tol = 1.0e3_wp * eps_wp

  !> A solve along positions lo..hi: per position the applied force and sliding friction (b)
  !> and the friction bound (beta) in u = s a, which bodies are boxed (at rest, beta > 0) and
  !> broken away, the solution u and the rates of each.
  type :: path_solution_type
    real(wp), allocatable, dimension(:) :: b, db, beta, u, du
    logical, allocatable :: boxed(:), broken(:), stuck(:)
    real(wp), allocatable :: sgn(:)
  end type path_solution_type

  type :: path_work_type
    integer :: n = 0                              !< bodies of the path last ordered
    integer :: wall = 0                           !< the wall row (before p_1), or 0
    real(wp) :: s = 1.0_wp                        !< orientation: u = s a
    real(wp) :: wall_coef = 0                     !< the wall's coefficient on its body
    integer, allocatable :: order(:)              !< (n) p_t: body at position t
    integer, allocatable :: edge(:)               !< (n) row between p_t and p_(t+1) (edge(n) unused)
    real(wp), allocatable :: coef(:)              !< (n) its coefficient on p_(t+1)
    integer, allocatable :: adj(:, :), degree(:)  !< (2, n), (n) body-body rows on each body
    integer, allocatable :: position(:)           !< (n) the position of each body
    type(path_solution_type) :: x, trial          !< the cluster's solve; a row's let-go tried
    !> The least forces (value, rate) of the rows at positions 0..n - 1 (0: the wall), and
    !> their bounds per body: lambda_t - lambda_(t-1) in [lo_t, hi_t].
    real(wp), allocatable, dimension(:) :: lo, dlo, hi, dhi, fw, dfw, bw, dbw
    logical, allocatable :: gone(:)               !< (0:n) the row at the position is let go
    ! Blocks of the pooling (a stack of up to n + 1, the wall's block and a block a body):
    ! first position, mass, sums, their value and its rate (block_value), held at 0 (the wall's).
    integer, allocatable :: first(:)
    real(wp), allocatable, dimension(:) :: bm, bb, bdb, bbeta, bx, bdx
    logical, allocatable :: fixed(:)
    !> (0:n - 1) the cycle through the ground of the row at each position (hold_path_rows), 0 none;
    !> (n) per cycle, its force-free rows still to visit, -1 once one is let go
    integer, allocatable :: cycle(:), remaining(:)
    logical, allocatable :: shut(:)               !< (0:n - 1) the row at the position is closed
    real(wp) :: tol_f = 0, tol_rate = 0           !< zero force and rate (the cluster's)
  end type path_work_type

contains

  !> Room for paths of up to n bodies (grown, never shrunk).
  subroutine path_reserve(work, n)
    type(path_work_type), intent(inout) :: work
    integer, intent(in) :: n
    if (allocated(work%order)) then
      if (size(work%order) >= n) return
      deallocate(work%order, work%edge, work%coef, work%adj, work%degree, work%position, work%lo, work%dlo, work%hi, &
        work%dhi, work%fw, work%dfw, work%bw, work%dbw, work%gone, work%first, work%bm, work%bb, work%bdb, &
        work%bbeta, work%bx, work%bdx, work%fixed, work%cycle, work%remaining, work%shut)
      call free_solution(work%x)
      call free_solution(work%trial)
    end if
    allocate(work%order(n), work%edge(n), work%coef(n), work%adj(2, n), work%degree(n), work%position(n), work%lo(n), &
      work%dlo(n), work%hi(n), work%dhi(n), work%fw(0:n), work%dfw(0:n), work%bw(0:n), work%dbw(0:n), &
      work%gone(0:n), work%first(n + 2), work%bm(n + 1), work%bb(n + 1), work%bdb(n + 1), work%bbeta(n + 1), &
      work%bx(n + 1), work%bdx(n + 1), work%fixed(n + 1), work%cycle(0:n), work%remaining(n), work%shut(0:n))
    call new_solution(work%x, n)
    call new_solution(work%trial, n)
  end subroutine path_reserve

  subroutine new_solution(x, n)
    type(path_solution_type), intent(inout) :: x
    integer, intent(in) :: n
    allocate(x%b(n), x%db(n), x%beta(n), x%u(n), x%du(n), x%boxed(n), x%broken(n), x%stuck(n), x%sgn(n))
  end subroutine new_solution

  subroutine free_solution(x)
    type(path_solution_type), intent(inout) :: x
    deallocate(x%b, x%db, x%beta, x%u, x%du, x%boxed, x%broken, x%stuck, x%sgn)
  end subroutine free_solution

  !> Whether the n bodies and the rows (all candidates) of a cluster form a path ordered one
  !> way (module header); if so, the path's order, edges, wall and orientation are in work.
  logical function path_order(work, n, row_body, row_normal) result(fits)
    type(path_work_type), intent(inout) :: work
    integer, intent(in) :: n, row_body(:, :)
    real(wp), intent(in) :: row_normal(:, :)
    fits = path_walk(work, n, row_body, row_normal)
    if (.not. fits) return
    work%s = 1.0_wp
    if (n > 1) then
      work%s = work%coef(1)
    else if (work%wall /= 0) then
      work%s = work%wall_coef
    end if
    fits = all(work%coef(1:n - 1) == work%s)
    if (work%wall /= 0) fits = fits .and. work%wall_coef == work%s
  end function path_order

  !> Whether the n bodies and the rows of a cluster form a path: each body in at most two
  !> rows, the body-body rows (-1, 1) or (1, -1), at most one wall, on an end body. If so,
  !> work has the bodies in path order from the wall's end (order, position), the row
  !> between positions t and t + 1 (edge) with its coefficient on the later body (coef), and
  !> the wall's row and its coefficient.
  logical function path_walk(work, n, row_body, row_normal) result(fits)
    type(path_work_type), intent(inout) :: work
    integer, intent(in) :: n, row_body(:, :)
    real(wp), intent(in) :: row_normal(:, :)
    integer :: k, i, t, prev, next, e, wall_body
    fits = .false.
    work%n = n
    work%wall = 0
    wall_body = 0
    work%degree(1:n) = 0
    do k = 1, size(row_body, 2)
      if (row_body(1, k) == 0 .or. row_body(2, k) == 0) then
        if (work%wall /= 0) return                          ! two walls: the forces are not unique
        e = merge(2, 1, row_body(1, k) == 0)
        if (abs(row_normal(e, k)) /= 1.0_wp) return
        work%wall = k
        work%wall_coef = row_normal(e, k)
        wall_body = row_body(e, k)
        cycle
      end if
      if (row_normal(1, k) /= -row_normal(2, k) .or. abs(row_normal(1, k)) /= 1.0_wp) return
      do e = 1, 2
        i = row_body(e, k)
        if (work%degree(i) == 2) return
        work%degree(i) = work%degree(i) + 1
        work%adj(work%degree(i), i) = k
      end do
    end do
    if (size(row_body, 2) - merge(1, 0, work%wall /= 0) /= n - 1) return
    ! Start at the wall's body (it must be an end) or at any end.
    work%order(1) = wall_body
    if (wall_body == 0) then
      do i = 1, n
        if (work%degree(i) <= 1) exit
      end do
      if (i > n) return
      work%order(1) = i
    else if (work%degree(wall_body) > 1) then
      return
    end if
    prev = 0
    do t = 1, n - 1
      i = work%order(t)
      k = work%adj(1, i)
      if (work%degree(i) == 2 .and. k == prev) k = work%adj(2, i)
      if (k == prev) return
      next = row_body(1, k) + row_body(2, k) - i
      work%edge(t) = k
      work%order(t + 1) = next
      work%coef(t) = row_normal(merge(1, 2, row_body(1, k) == next), k)
      prev = k
    end do
    do t = 1, n
      work%position(work%order(t)) = t
    end do
    fits = .true.
  end function path_walk

  !> The mode of the cluster path_order accepted last (module header; the arguments as
  !> impact1d_cluster_mode's cluster_mode, every row a candidate). Out: active, stuck, sgn,
  !> acceleration and its rate (the solve's, not yet the groups' exact means).
  subroutine path_mode(work, mass, force, rate, friction, static_friction, velocity, row_body, row_normal, &
      acceleration, acc_rate, active, stuck, sgn)
    type(path_work_type), intent(inout) :: work
    real(wp), intent(in) :: mass(:), force(:), rate(:), friction(:), static_friction(:), velocity(:)
    integer, intent(in) :: row_body(:, :)
    real(wp), intent(in) :: row_normal(:, :)
    real(wp), intent(out) :: acceleration(:), acc_rate(:), sgn(:)
    logical, intent(out) :: active(:), stuck(:)
    integer :: n, t, i
    n = work%n
    work%tol_f = rel_tol * (sum(abs(force(1:n))) + 2.0_wp * sum(static_friction(1:n))) + tiny(1.0_wp)
    work%tol_rate = rel_tol * sum(abs(rate(1:n)))
    call solve_range(work, work%x, 1, n, work%wall /= 0, mass, force, rate, friction, static_friction, velocity)
    do t = 1, n
      i = work%order(t)
      acceleration(i) = work%s * work%x%u(t) + 0.0_wp
      acc_rate(i) = work%s * work%x%du(t) + 0.0_wp
      if (work%x%stuck(t)) acceleration(i) = 0.0_wp
      stuck(i) = work%x%stuck(t)
      sgn(i) = work%x%sgn(t)
    end do
    call least_forces(work, mass)
    call hold_path_rows(work, mass, force, rate, friction, static_friction, velocity, row_body, row_normal, &
      acceleration, acc_rate, active)
  end subroutine path_mode

  !> Positions lo..hi solved alone (the wall with them if wall): static friction first, the
  !> bodies it cannot hold broken away to sliding friction and solved again until none is
  !> (impact1d_cluster_mode's iteration); then which bodies stick and which way the others
  !> slide (its mode_of).
  subroutine solve_range(work, x, lo, hi, wall, mass, force, rate, friction, static_friction, velocity)
    type(path_work_type), intent(inout) :: work
    type(path_solution_type), intent(inout) :: x
    integer, intent(in) :: lo, hi
    logical, intent(in) :: wall
    real(wp), intent(in) :: mass(:), force(:), rate(:), friction(:), static_friction(:), velocity(:)
    integer :: t, i, solves
    logical :: more
    x%broken(lo:hi) = .false.
    do solves = 1, hi - lo + 2
      call set_bounds(work, x, lo, hi, force, rate, friction, static_friction, velocity)
      call pool(work, x, lo, hi, wall, mass)
      more = .false.
      do t = lo, hi
        if (.not. x%boxed(t) .or. x%broken(t)) cycle
        if (still(mass(work%order(t)), x%u(t), x%du(t), work%tol_f, work%tol_rate)) cycle
        x%broken(t) = .true.
        more = .true.
      end do
      if (.not. more) exit
    end do
    do t = lo, hi
      i = work%order(t)
      x%stuck(t) = .false.
      x%sgn(t) = 0.0_wp
      if (velocity(i) /= 0.0_wp) then
        if (friction(i) > 0.0_wp) x%sgn(t) = sign(1.0_wp, velocity(i))
      else if (x%boxed(t) .or. x%broken(t)) then
        ! A body at rest that moves slides the way it leaves; one broken away with no sliding
        ! friction (mu = 0 < mus, no longer boxed) too, so that its stop is watched (as
        ! impact1d_cluster_mode's mode_of).
        if (still(mass(i), x%u(t), x%du(t), work%tol_f, work%tol_rate)) then
          x%stuck(t) = x%boxed(t)
          cycle
        end if
        x%sgn(t) = work%s * sign(1.0_wp, merge(x%du(t), x%u(t), abs(mass(i) * x%u(t)) <= work%tol_f))
      end if
    end do
  end subroutine solve_range

  !> Each position's b (applied force, sliding friction), its rate and its friction bound,
  !> in u = s a (impact1d_cluster_mode's build_lcp: a body at rest is boxed by s, or by c
  !> once broken away; sliding friction acts against v).
  subroutine set_bounds(work, x, lo, hi, force, rate, friction, static_friction, velocity)
    type(path_work_type), intent(in) :: work
    type(path_solution_type), intent(inout) :: x
    integer, intent(in) :: lo, hi
    real(wp), intent(in) :: force(:), rate(:), friction(:), static_friction(:), velocity(:)
    integer :: t, i
    do t = lo, hi
      i = work%order(t)
      x%beta(t) = 0.0_wp
      x%b(t) = force(i)
      if (velocity(i) /= 0.0_wp) then
        x%b(t) = force(i) - friction(i) * sign(1.0_wp, velocity(i))
      else if (static_friction(i) > 0.0_wp) then
        x%beta(t) = merge(friction(i), static_friction(i), x%broken(t))
      end if
      x%boxed(t) = x%beta(t) > 0.0_wp
      x%b(t) = work%s * x%b(t)
      x%db(t) = work%s * rate(i)
    end do
  end subroutine set_bounds

  !> Pool adjacent violators (module header) over positions lo..hi: u and du there.
  subroutine pool(work, x, lo, hi, wall, mass)
    type(path_work_type), intent(inout) :: work
    type(path_solution_type), intent(inout) :: x
    integer, intent(in) :: lo, hi
    logical, intent(in) :: wall
    real(wp), intent(in) :: mass(:)
    integer :: top, t, j
    top = 0
    if (wall) then
      top = 1
      work%first(1) = lo - 1
      work%fixed(1) = .true.
      call block_value(work, 1)
    end if
    do t = lo, hi
      top = top + 1
      work%first(top) = t
      work%fixed(top) = .false.
      work%bm(top) = mass(work%order(t))
      work%bb(top) = x%b(t)
      work%bdb(top) = x%db(t)
      work%bbeta(top) = x%beta(t)
      call block_value(work, top)
      do while (top > 1)
        if (.not. greater(work%bx(top - 1), work%bdx(top - 1), work%bx(top), work%bdx(top), &
          work%tol_f / (work%bm(top - 1) + work%bm(top)), work%tol_rate / (work%bm(top - 1) + work%bm(top)))) exit
        top = top - 1
        work%fixed(top) = work%fixed(top) .or. work%fixed(top + 1)
        work%bm(top) = work%bm(top) + work%bm(top + 1)
        work%bb(top) = work%bb(top) + work%bb(top + 1)
        work%bdb(top) = work%bdb(top) + work%bdb(top + 1)
        work%bbeta(top) = work%bbeta(top) + work%bbeta(top + 1)
        call block_value(work, top)
      end do
    end do
    work%first(top + 1) = hi + 1
    do j = 1, top
      do t = max(work%first(j), lo), work%first(j + 1) - 1
        x%u(t) = work%bx(j)
        x%du(t) = work%bdx(j)
      end do
    end do
  end subroutine pool

  !> Block j's value and rate (bx, bdx): the minimiser of its summed f (a pair,
  !> lexicographic: the soft threshold of (b, db) by beta, ties within rounding decided by
  !> the rate), 0 for the wall's block.
  pure subroutine block_value(work, j)
    type(path_work_type), intent(inout) :: work
    integer, intent(in) :: j
    real(wp) :: b, db, k
    work%bx(j) = 0.0_wp
    work%bdx(j) = 0.0_wp
    if (work%fixed(j)) return
    b = work%bb(j)
    db = work%bdb(j)
    k = work%bbeta(j)
    if (greater(b, db, k, 0.0_wp, work%tol_f, work%tol_rate)) then
      work%bx(j) = max(b - k, 0.0_wp) / work%bm(j)
      work%bdx(j) = db / work%bm(j)
    else if (greater(-k, 0.0_wp, b, db, work%tol_f, work%tol_rate)) then
      work%bx(j) = min(b + k, 0.0_wp) / work%bm(j)
      work%bdx(j) = db / work%bm(j)
    end if
  end subroutine block_value

  !> Whether the pair (x1, dx1) is above (x2, dx2): lexicographically, values within tol
  !> (rounding) equal and then rates within dtol.
  pure logical function greater(x1, dx1, x2, dx2, tol, dtol)
    real(wp), intent(in) :: x1, dx1, x2, dx2, tol, dtol
    greater = x1 - x2 > tol .or. (abs(x1 - x2) <= tol .and. dx1 - dx2 > dtol)
  end function greater

  !> The least force distribution (module header) in fw (value) and dfw (rate), at 0..n - 1:
  !> position 0 the wall's force, t the force of the row between p_t and p_(t+1). A moving
  !> body's friction is fixed (lo = hi); a stuck body's lies in [-beta, beta].
  subroutine least_forces(work, mass)
    type(path_work_type), intent(inout) :: work
    real(wp), intent(in) :: mass(:)
    integer :: t, i, n
    real(wp) :: e, de, f
    n = work%n
    associate (x => work%x)
      do t = 1, n
        i = work%order(t)
        e = x%b(t) - mass(i) * x%u(t)
        de = x%db(t) - mass(i) * x%du(t)
        f = 0.0_wp
        if (x%stuck(t)) then
          e = x%b(t)
          de = x%db(t)
          f = x%beta(t)
        else if (x%boxed(t)) then
          e = e - x%beta(t) * work%s * x%sgn(t)
        end if
        work%lo(t) = e - f
        work%hi(t) = e + f
        work%dlo(t) = de
        work%dhi(t) = de
      end do
    end associate
    ! From the left: lambda_t >= lambda_(t-1) + lo_t; from the right: lambda_(t-1) >= lambda_t - hi_t.
    work%fw(0) = 0.0_wp
    work%dfw(0) = 0.0_wp
    do t = 1, n - 1
      call lex_max(work, work%fw(t - 1) + work%lo(t), work%dfw(t - 1) + work%dlo(t), 0.0_wp, 0.0_wp, work%fw(t), work%dfw(t))
    end do
    work%bw(n) = 0.0_wp
    work%dbw(n) = 0.0_wp
    do t = n, 1, -1
      call lex_max(work, work%bw(t) - work%hi(t), work%dbw(t) - work%dhi(t), 0.0_wp, 0.0_wp, work%bw(t - 1), work%dbw(t - 1))
    end do
    do t = 0, n - 1
      call lex_max(work, work%fw(t), work%dfw(t), work%bw(t), work%dbw(t), work%fw(t), work%dfw(t))
    end do
  end subroutine least_forces

  !> The lexicographic larger of two forces with their rates (greater).
  pure subroutine lex_max(work, x1, dx1, x2, dx2, x, dx)
    type(path_work_type), intent(in) :: work
    real(wp), value :: x1, dx1, x2, dx2
    real(wp), intent(out) :: x, dx
    if (greater(x1, dx1, x2, dx2, work%tol_f, work%tol_rate)) then
      x = x1
      dx = dx1
    else
      x = x2
      dx = dx2
    end if
  end subroutine lex_max

  !> Held rows (module header), as impact1d_cluster_mode's hold_rows and impact1d_body_mode's
  !> prefer_friction choose them: first those with force (above tol_f, or at zero and rising);
  !> then the closed force-free rows, all held but one on each cycle through the ground. The
  !> closed rows and stuck bodies join the bodies to each other and to the ground (the wall,
  !> stuck bodies); along a path the only cycles are the runs of closed rows between two
  !> stuck bodies or the wall and a stuck body. A force-free row off a cycle is held (its ends
  !> are not otherwise joined: a frictionless body resting on a stuck one keeps its row). On a
  !> cycle, in row order, the first row that can be let go with the bodies moving alike (a
  !> fresh solve of the two sides: a body that broke away pushed through the row may stick
  !> without it) is let go, or else the cycle's last, which the dense solve never holds.
  subroutine hold_path_rows(work, mass, force, rate, friction, static_friction, velocity, row_body, row_normal, &
      acceleration, acc_rate, active)
    type(path_work_type), intent(inout) :: work
    real(wp), intent(in) :: mass(:), force(:), rate(:), friction(:), static_friction(:), velocity(:)
    real(wp), intent(in) :: row_normal(:, :), acceleration(:), acc_rate(:)
    integer, intent(in) :: row_body(:, :)
    logical, intent(out) :: active(:)
    integer :: t, k, c
    active = .false.
    work%gone(0:work%n) = .false.
    do t = 0, work%n - 1
      k = row_at(t)
      work%shut(t) = .false.
      if (k == 0) cycle
      ! Closed and staying closed: n.a and its rate zero (cluster_mode's hold_rows' test).
      work%shut(t) = row_closed(row_body, row_normal, k, mass, acceleration, acc_rate, work%tol_f, work%tol_rate)
      if (work%fw(t) <= work%tol_f .and. (work%fw(t) < -work%tol_f .or. work%dfw(t) <= work%tol_rate)) cycle
      active(k) = work%shut(t)
    end do
    call find_cycles()
    do k = 1, size(active)
      t = 0
      if (k /= work%wall) t = min(work%position(row_body(1, k)), work%position(row_body(2, k)))
      if (active(k) .or. .not. work%shut(t)) cycle
      active(k) = .true.
      c = work%cycle(t)
      if (c == 0) cycle
      if (work%remaining(c) < 0) cycle                  ! its cycle is cut: its ends are not otherwise joined
      work%remaining(c) = work%remaining(c) - 1
      if (work%remaining(c) > 0) then
        if (.not. moves_alike_without(t)) cycle
        work%gone(t) = .true.
      end if
      active(k) = .false.
      work%remaining(c) = -1
    end do

  contains

    !> The row at position t (0 the wall's, else between p_t and p_(t+1)), 0 if none.
    integer function row_at(t)
      integer, intent(in) :: t
      row_at = work%wall
      if (t > 0) row_at = work%edge(t)
    end function row_at

    !> work%cycle and work%remaining: a closed row's cycle is numbered by its run's first
    !> position + 1 when the run starts at the ground (the wall's row, or a stuck body) and
    !> ends at a stuck body; the force-free rows (not yet active) counted per cycle.
    subroutine find_cycles()
      integer :: t, start
      logical :: grounded
      start = -1
      do t = 0, work%n - 1
        work%cycle(t) = 0
        if (.not. work%shut(t)) then
          start = -1
          cycle
        end if
        if (t == 0) start = 0
        if (t > 0) then
          if (work%x%stuck(t)) start = t
        end if
        if (start >= 0) work%cycle(t) = start + 1
      end do
      grounded = .false.
      work%remaining(1:work%n) = 0
      do t = work%n - 1, 0, -1
        if (t < work%n - 1) grounded = grounded .and. work%shut(t + 1)
        grounded = grounded .or. work%x%stuck(t + 1)
        if (.not. grounded) work%cycle(t) = 0
        if (work%cycle(t) == 0) cycle
        if (.not. active(row_at(t))) work%remaining(work%cycle(t)) = work%remaining(work%cycle(t)) + 1
      end do
    end subroutine find_cycles

    !> Whether the bodies move as they do with the rows let go so far and the row at t too:
    !> the stretch of the path it was in solved afresh as two.
    logical function moves_alike_without(t)
      integer, intent(in) :: t
      integer :: lo, hi, j
      lo = t
      do while (lo > 1)
        if (work%gone(lo - 1)) exit
        lo = lo - 1
      end do
      lo = max(lo, 1)
      hi = t + 1
      do while (hi < work%n)
        if (work%gone(hi)) exit
        hi = hi + 1
      end do
      hi = min(hi, work%n)
      if (t > 0) call solve_range(work, work%trial, lo, t, lo == 1 .and. work%wall /= 0 .and. .not. work%gone(0), &
        mass, force, rate, friction, static_friction, velocity)
      if (t < work%n) call solve_range(work, work%trial, t + 1, hi, .false., mass, force, rate, friction, &
        static_friction, velocity)
      moves_alike_without = .true.
      do j = lo, hi
        moves_alike_without = moves_alike_without .and. (work%trial%stuck(j) .eqv. work%x%stuck(j)) .and. &
          work%trial%sgn(j) == work%x%sgn(j) .and. &
          abs(mass(work%order(j)) * (work%trial%u(j) - work%x%u(j))) <= work%tol_f .and. &
          abs(mass(work%order(j)) * (work%trial%du(j) - work%x%du(j))) <= work%tol_rate
      end do
    end function moves_alike_without
  end subroutine hold_path_rows

  !> Whether a body's acceleration a and its rate da are zero (impact1d_cluster_mode's still).
  pure logical function still(mass, a, da, tol_f, tol_rate)
    real(wp), intent(in) :: mass, a, da, tol_f, tol_rate
    still = abs(mass * a) <= tol_f .and. abs(mass * da) <= tol_rate
  end function still
end module impact1d_path_mode

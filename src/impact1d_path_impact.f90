!> The joint perfectly inelastic impact of closed rows that form a path (issue 20 item 3;
!> docs/method.md section 9): impact1d_cluster_impact's projection, in O(n) instead of a
!> dense LCP in the impulses. A train taking up a coupler is one: the moving part's taut
!> couplers, the coupler coming taut and the standing part's closed buffers.
!>
!> Which groups: the rows form a path (impact1d_path_mode's path_walk) whose order turns at
!> most once, and a wall, if any, at the end the path starts from, below it. In u = sigma w
!> (sigma the first row's coefficient on its later body) the rows then say u_1 <= .. <= u_p
!> >= u_(p+1) >= .. >= u_n (p = n when the order never turns) and 0 <= u_1 with the wall:
!> two ascending chains meeting at their common top p, a tree. The velocity after is the
!> isotonic regression of v on that order weighted by the masses (the kinetic-energy
!> projection): each chain pooled from its foot (pooling adjacent violators; the wall a
!> block held at 0), then at the top the chains' blocks joined into p's block, the larger
!> first, while they stand above it (the tree's pooling). Impulses follow from the momentum
!> of each body, summed along each chain from its foot.
!> As impact1d_cluster_impact: nothing changes unless a row approaches beyond its rounding;
!> pushed rows are those whose impulse is above rounding of the largest momentum, and the
!> bodies they join get one velocity exactly (their mean weighted by mass; 0 at a wall).
module impact1d_path_impact
  use impact1d_kinds, only: wp, eps_wp
  use impact1d_clusters, only: uf_join, group_means, row_rate
  use impact1d_path_mode, only: path_work_type, path_reserve, path_walk
  implicit none
  private
  public :: path_impact_work_type, path_impact_reserve, path_projection

  !> Blocks of one chain's pooling, a stack from its foot: the block's first position
  !> (nearest the foot), its mass and momentum, held at 0 (the wall's).
  type :: stack_type
    integer :: top = 0
    integer, allocatable :: first(:)
    real(wp), allocatable :: m(:), mu(:)
    logical, allocatable :: fixed(:)
  end type stack_type

  type :: path_impact_work_type
    type(path_work_type) :: path
    real(wp), allocatable :: u(:), p(:)            !< (n) velocities after in u; (0:n) impulses by position
    type(stack_type) :: left, right                !< (n + 1) the two chains' blocks
    integer, allocatable :: root(:)                !< (0:n) union-find of the pushed rows
    real(wp), allocatable :: group_mass(:), group_sum(:)   !< (0:n) scratch of group_means
  end type path_impact_work_type

contains

  !> Room for groups of up to n bodies (grown, never shrunk).
  subroutine path_impact_reserve(work, n)
    type(path_impact_work_type), intent(inout) :: work
    integer, intent(in) :: n
    call path_reserve(work%path, n)
    if (allocated(work%u)) then
      if (size(work%u) >= n) return
      deallocate(work%u, work%p, work%root, work%group_mass, work%group_sum, work%left%first, work%left%m, &
        work%left%mu, work%left%fixed, work%right%first, work%right%m, work%right%mu, work%right%fixed)
    end if
    allocate(work%u(n), work%p(0:n), work%root(0:n), work%group_mass(0:n), work%group_sum(0:n), &
      work%left%first(n + 1), work%left%m(n + 1), work%left%mu(n + 1), work%left%fixed(n + 1), &
      work%right%first(n + 1), work%right%m(n + 1), work%right%mu(n + 1), work%right%fixed(n + 1))
  end subroutine path_impact_reserve

  !> The joint inelastic impact (module header) of bodies 1..size(mass) on the rows (all
  !> closed; ends row_body, 0 = ground; coefficients row_normal); tol: each row's rounding
  !> level of a normal velocity. fits: the rows are such a path (else nothing is computed);
  !> then v_after, impulse (P per row) and pushed, as impact1d_cluster_impact's.
  subroutine path_projection(work, mass, velocity, row_body, row_normal, tol, v_after, impulse, pushed, fits)
    type(path_impact_work_type), intent(inout) :: work
    real(wp), intent(in) :: mass(:), velocity(:), row_normal(:, :), tol(:)
    integer, intent(in) :: row_body(:, :)
    real(wp), intent(out) :: v_after(:), impulse(:)
    logical, intent(out) :: pushed(:), fits
    integer :: n, k, t, top, i
    real(wp) :: sigma, p_tol
    logical :: joined
    n = size(mass)
    fits = path_walk(work%path, n, row_body, row_normal)
    if (.not. fits) return
    sigma = 1.0_wp
    if (n > 1) sigma = work%path%coef(1)
    if (n == 1 .and. work%path%wall /= 0) sigma = work%path%wall_coef
    if (work%path%wall /= 0) fits = work%path%wall_coef == sigma
    ! The top: where the order turns, else the last body.
    top = n
    do t = 2, n - 1
      if (work%path%coef(t) /= sigma) then
        top = t
        exit
      end if
    end do
    do t = top, n - 1
      if (work%path%coef(t) == sigma) fits = .false.
    end do
    if (.not. fits) return
    v_after(1:n) = velocity(1:n)
    impulse = 0.0_wp
    pushed = .false.
    do k = 1, size(tol)
      if (row_rate(row_body, row_normal, k, velocity) < -tol(k)) exit
    end do
    if (k > size(tol)) return                ! nothing approaches: nothing changes
    call regress(work, mass, velocity, sigma, top)
    ! Impulses: a body's momentum change is what its two rows give it, summed along each
    ! chain from its foot, so that a chain that does not move gets none, not the rounding
    ! of the other chain's sum (with a wall the left chain is summed from the top).
    work%p(n) = 0.0_wp
    do t = n, top + 1, -1
      i = work%path%order(t)
      work%p(t - 1) = work%p(t) - mass(i) * (work%u(t) - sigma * velocity(i))
    end do
    work%p(0) = 0.0_wp
    if (work%path%wall /= 0) then
      do t = top, 1, -1
        i = work%path%order(t)
        if (t == top) then
          work%p(t - 1) = mass(i) * (work%u(t) - sigma * velocity(i)) - work%p(t)
        else
          work%p(t - 1) = work%p(t) + mass(i) * (work%u(t) - sigma * velocity(i))
        end if
      end do
    else
      do t = 1, top - 1
        i = work%path%order(t)
        work%p(t) = work%p(t - 1) - mass(i) * (work%u(t) - sigma * velocity(i))
      end do
    end if
    p_tol = 0.0_wp
    do i = 1, n
      p_tol = max(p_tol, mass(i) * abs(velocity(i)))
    end do
    p_tol = 1.0e3_wp * eps_wp * p_tol
    do t = 0, n - 1
      k = work%path%wall
      if (t > 0) k = work%path%edge(t)
      if (k == 0) cycle
      impulse(k) = max(work%p(t), 0.0_wp)
      pushed(k) = impulse(k) > p_tol
    end do
    do t = 1, n
      v_after(work%path%order(t)) = sigma * work%u(t) + 0.0_wp
    end do
    work%root(0:n) = [(i, i = 0, n)]
    do k = 1, size(pushed)
      if (pushed(k)) joined = uf_join(work%root, row_body(1, k), row_body(2, k))
    end do
    call group_means(work%root, mass, v_after, work%group_mass, work%group_sum)
  end subroutine path_projection

  !> The weighted isotonic regression of sigma v on the two chains meeting at top (module
  !> header), in work%u by position.
  subroutine regress(work, mass, velocity, sigma, top)
    type(path_impact_work_type), intent(inout) :: work
    real(wp), intent(in) :: mass(:), velocity(:), sigma
    integer, intent(in) :: top
    integer :: n, t, j, lo, hi
    real(wp) :: m, mu
    logical :: fixed
    n = work%path%n
    work%left%top = 0
    work%right%top = 0
    if (work%path%wall /= 0) call push(work%left, 0, 1.0_wp, 0.0_wp, .true.)
    do t = 1, top - 1
      call push(work%left, t, mass(work%path%order(t)), mass(work%path%order(t)) * (sigma * velocity(work%path%order(t))), &
        .false.)
    end do
    do t = n, top + 1, -1
      call push(work%right, t, mass(work%path%order(t)), &
        mass(work%path%order(t)) * (sigma * velocity(work%path%order(t))), .false.)
    end do
    ! The top's block takes the chains' top blocks, the larger first, while above it.
    m = mass(work%path%order(top))
    mu = m * (sigma * velocity(work%path%order(top)))
    fixed = .false.
    lo = top
    hi = top
    do
      j = 0
      if (work%left%top > 0) then
        if (value_of(work%left, work%left%top) > block_value(m, mu, fixed)) j = 1
      end if
      if (work%right%top > 0) then
        if (value_of(work%right, work%right%top) > block_value(m, mu, fixed)) then
          if (j == 0) then
            j = 2
          else if (value_of(work%right, work%right%top) > value_of(work%left, work%left%top)) then
            j = 2
          end if
        end if
      end if
      if (j == 0) exit
      if (j == 1) then
        call take(work%left)
        lo = work%left%first(work%left%top + 1)
      else
        call take(work%right)
        hi = work%right%first(work%right%top + 1)
      end if
    end do
    ! Positions: the top's block lo..hi; a left block from its first to the next one's (the
    ! last to lo); a right block from its first down to the next one's (the last to hi).
    work%u(max(lo, 1):hi) = block_value(m, mu, fixed)
    do j = 1, work%left%top
      work%u(max(work%left%first(j), 1):merge(work%left%first(j + 1) - 1, lo - 1, j < work%left%top)) = &
        value_of(work%left, j)
    end do
    do j = 1, work%right%top
      work%u(merge(work%right%first(j + 1) + 1, hi + 1, j < work%right%top):work%right%first(j)) = &
        value_of(work%right, j)
    end do

  contains

    !> The stack's top block joined into the top's block.
    subroutine take(st)
      type(stack_type), intent(inout) :: st
      m = m + st%m(st%top)
      mu = mu + st%mu(st%top)
      fixed = fixed .or. st%fixed(st%top)
      st%top = st%top - 1
    end subroutine take
  end subroutine regress

  !> A block for position t on the stack, pooled with those below while above them.
  subroutine push(st, t, m, mu, fixed)
    type(stack_type), intent(inout) :: st
    integer, intent(in) :: t
    real(wp), intent(in) :: m, mu
    logical, intent(in) :: fixed
    st%top = st%top + 1
    st%first(st%top) = t
    st%m(st%top) = m
    st%mu(st%top) = mu
    st%fixed(st%top) = fixed
    do while (st%top > 1)
      if (value_of(st, st%top - 1) <= value_of(st, st%top)) exit
      st%m(st%top - 1) = st%m(st%top - 1) + st%m(st%top)
      st%mu(st%top - 1) = st%mu(st%top - 1) + st%mu(st%top)
      st%fixed(st%top - 1) = st%fixed(st%top - 1) .or. st%fixed(st%top)
      st%top = st%top - 1
    end do
  end subroutine push

  pure real(wp) function value_of(st, j)
    type(stack_type), intent(in) :: st
    integer, intent(in) :: j
    value_of = block_value(st%m(j), st%mu(j), st%fixed(j))
  end function value_of

  !> A block's velocity: its momentum over its mass, 0 when held by the wall.
  pure real(wp) function block_value(m, mu, fixed)
    real(wp), intent(in) :: m, mu
    logical, intent(in) :: fixed
    block_value = 0.0_wp
    if (.not. fixed) block_value = mu / m
  end function block_value
end module impact1d_path_impact

!> The mode solve of one cluster of n bodies (issue 19, stage 4; docs/method.md, "N bodies:
!> the cluster's mode solve"): which closed rows are held, which bodies at rest stick, the
!> accelerations. Called per cluster by impact1d_body_mode (impact1d_path_mode for a path).
!>
!> The problem at one instant. Bodies i = 1..n: mass m_i, applied force y_i (external and
!> elastic) with its right derivative dy_i, sliding bound c_i, static bound s_i >= c_i,
!> velocity v_i. Rows k: ends a, b (0 = the ground), coefficients (n_a, n_b) on (x_a, x_b);
!> candidate rows (closed, zero normal velocity) may push: lambda_k >= 0, n_k.a >= 0,
!> lambda_k n_k.a = 0. A sliding body (v_i /= 0) feels -c_i sgn(v_i). A body at rest with
!> s_i > 0 feels F_i in [-beta_i, beta_i], with a_i = 0 inside the bound and F_i =
!> -beta_i sgn(a_i) when it moves. This is the LCP of Gauss's principle with friction
!> (a convex QP: the accelerations are unique), in the unknowns (lambda_k, rho_i = F_i +
!> beta_i, mu_i = m_i a_i^-), solved by impact1d_lcp (Lemke, lexicographic).
!>
!> What it guarantees (status = cluster_solved):
!> - The mode that holds just AFTER the instant: ties (a holding force exactly at its
!>   bound, a contact force exactly 0) are decided by the rate dy (as the two-body engine's
!>   mode solve did).
!> - Static above sliding (METHOD 8), stick preferred: the problem is solved with beta = s
!>   for every body at rest; bodies it moves break away and are solved again with beta = c
!>   (their F = -c sgn a), until no more break away (at most n + 1 solves).
!> - Exactness: a stuck body has a = 0 exactly; bodies joined by held rows of the form
!>   n = (-1, 1) or (1, -1), or a wall, share one acceleration exactly: 0 when joined to the
!>   ground or to a stuck body, else their mass-weighted mean (closed gaps do not creep).
!> - Active (held) rows: the closed rows carrying force, then, in row order, the closed
!>   force-free rows whose ends are not yet joined (the ground and stuck bodies counting as
!>   joined) - the choice of tests/exact_nbody.py and, where the set is unique, of the
!>   two-body engine's enumerator (since removed).
!> - No allocation: the caller sizes a cluster_work_type once (cluster_reserve).
module impact1d_cluster_mode
  use impact1d_kinds, only: wp, eps_wp
  use impact1d_clusters, only: uf_join, group_means, row_coupling, row_closed
  use impact1d_lcp, only: lcp_work_type, lcp_reserve, lcp_solve, lcp_basis_values, lcp_solved, &
    lcp_too_large
  implicit none
  private
  public :: cluster_work_type, cluster_reserve, cluster_mode, cluster_solved

  integer, parameter :: cluster_solved = 0    !< otherwise an impact1d_lcp status

  !> Relative size of a zero force (as the two-body engine's mode solve's tolerance was).
  real(wp), parameter :: rel_tol = 1.0e3_wp * eps_wp

  !> The mode solve's memory, owned by the caller and sized once (cluster_reserve).
  type :: cluster_work_type
    integer :: max_bodies = 0, max_rows = 0
    type(lcp_work_type) :: lcp
    integer :: size = 0, n_boxed = 0, n_free_rows = 0   !< the last LCP: unknowns, boxed bodies, candidate rows
    real(wp), allocatable :: m(:, :)           !< (s, s) LCP matrix, s = max_rows + 2 max_bodies
    real(wp), allocatable :: q(:), dq(:)       !< (s) its right-hand side and rate
    real(wp), allocatable :: z(:), w(:), dz(:), dw(:)   !< (s) solution and its rate
    real(wp), allocatable :: beta(:)           !< (max_bodies) friction bound of a boxed body
    real(wp), allocatable :: base(:)           !< (max_bodies) y + sliding friction - beta (boxed)
    real(wp), allocatable :: da(:)             !< (max_bodies) rate of the acceleration
    integer, allocatable :: row_var(:)         !< (max_rows) LCP unknown of candidate row k, else 0
    integer, allocatable :: slot(:)            !< (max_bodies) box slot of body i (rho at size_rows + slot), else 0
    integer, allocatable :: root(:)            !< (0:max_bodies) union-find parent; 0 is the ground
    logical, allocatable :: broken(:)          !< (max_bodies) at rest, broken away: bound c
    real(wp), allocatable :: group_mass(:), group_sum(:)   !< (0:max_bodies) per union-find root: sum m, sum m a
    !> Friction contacts between two of the cluster's bodies at relative rest (&friction; the
    !> caller sets n_pairs and the pair_ inputs, 0 by default): each a box on the relative
    !> coordinate x_b - x_a (J = e_b - e_a), as a body's box is on x_i: the force on b within
    !> [-static, static], its opposite on a, relative acceleration 0 inside the bound; broken
    !> away, the bound is pair_slide. Out: pair_stuck, pair_sgn (the relative acceleration's
    !> way when it slides: the force is -pair_slide pair_sgn on b).
    integer :: max_pairs = 0, n_pairs = 0
    integer, allocatable :: pair_body(:, :)    !< (2, max_pairs) local ends a, b
    real(wp), allocatable :: pair_static(:), pair_slide(:), pair_sgn(:)   !< (max_pairs)
    logical, allocatable :: pair_stuck(:)      !< (max_pairs)
    real(wp), allocatable, private :: pair_beta(:)   !< (max_pairs) its bound in this solve
    integer, allocatable, private :: pair_slot(:)    !< (max_pairs) its box slot (after the bodies'), else 0
    logical, allocatable, private :: pair_broken(:)  !< (max_pairs) broken away: bound pair_slide
    !> Rows whose ends are solved in frames that accelerate apart (a body at rest on a belt of
    !> sine speed is solved in its belt's frame, a = b + a': impact1d_body_mode's solve_cluster
    !> sets these, biased false by default): row k's w = n_k.a' + row_bias(k) is the rows'
    !> acceleration n_k.a in the still frame, row_bias = n_k.b (its rate row_bias_rate).
    logical :: biased = .false.
    real(wp), allocatable :: row_bias(:), row_bias_rate(:)   !< (max_rows)
  end type cluster_work_type

contains

  !> Size the work for clusters of up to max_bodies bodies and max_rows rows (and max_pairs
  !> friction contacts at relative rest, 0 when not given).
  subroutine cluster_reserve(work, max_bodies, max_rows, max_pairs)
    type(cluster_work_type), intent(inout) :: work
    integer, intent(in) :: max_bodies, max_rows
    integer, intent(in), optional :: max_pairs
    integer :: s, np, mb, mr
    np = 0
    if (present(max_pairs)) np = max_pairs
    if (np > work%max_pairs .or. .not. allocated(work%pair_body)) then
      if (allocated(work%pair_body)) deallocate(work%pair_body, work%pair_static, work%pair_slide, work%pair_sgn, &
        work%pair_stuck, work%pair_beta, work%pair_slot, work%pair_broken)
      work%max_pairs = max(np, work%max_pairs)
      allocate(work%pair_body(2, work%max_pairs), work%pair_static(work%max_pairs), work%pair_slide(work%max_pairs), &
        work%pair_sgn(work%max_pairs), work%pair_stuck(work%max_pairs), work%pair_beta(work%max_pairs), &
        work%pair_slot(work%max_pairs), work%pair_broken(work%max_pairs))
      if (allocated(work%m)) deallocate(work%m)    ! (the matrix grows with the pairs' unknowns)
    end if
    if (work%max_bodies >= max_bodies .and. work%max_rows >= max_rows .and. allocated(work%m)) return
    if (allocated(work%q)) deallocate(work%q, work%dq, work%z, work%w, work%dz, work%dw, &
      work%beta, work%base, work%da, work%row_var, work%slot, work%root, work%broken, &
      work%group_mass, work%group_sum, work%row_bias, work%row_bias_rate)
    if (allocated(work%m)) deallocate(work%m)
    mb = max(max_bodies, work%max_bodies)
    mr = max(max_rows, work%max_rows)
    s = mr + 2 * (mb + work%max_pairs)
    allocate(work%m(s, s), work%q(s), work%dq(s), work%z(s), work%w(s), work%dz(s), work%dw(s), &
      work%beta(mb), work%base(mb), work%da(mb), work%row_var(mr), work%row_bias(mr), work%row_bias_rate(mr), &
      work%slot(mb), work%root(0:mb), work%broken(mb), &
      work%group_mass(0:mb), work%group_sum(0:mb))
    call lcp_reserve(work%lcp, s)
    work%max_bodies = mb
    work%max_rows = mr
  end subroutine cluster_reserve

  !> The mode of one cluster (module header). Bodies 1..n = size(mass) (the body arrays of
  !> size n at least); rows 1..size(candidate) with ends row_body(1:2, k) in 0..n (0 = ground)
  !> and coefficients row_normal(1:2, k).
  !> Out: acceleration (n), active (rows held), stuck (bodies held by static friction), sgn
  !> (friction acts as -c sgn on a moving body), contact_force (lambda, 0 off the candidates),
  !> friction_force (n), status (cluster_solved, else an LCP status: the outputs are not a mode).
  subroutine cluster_mode(work, mass, force, rate, friction, static_friction, velocity, row_body, &
      row_normal, candidate, acceleration, active, stuck, sgn, contact_force, friction_force, status)
    type(cluster_work_type), intent(inout) :: work
    real(wp), intent(in) :: mass(:), force(:), rate(:), friction(:), static_friction(:), velocity(:)
    integer, intent(in) :: row_body(:, :)
    real(wp), intent(in) :: row_normal(:, :)
    logical, intent(in) :: candidate(:)
    real(wp), intent(out) :: acceleration(:), contact_force(:), friction_force(:), sgn(:)
    logical, intent(out) :: active(:), stuck(:)
    integer, intent(out) :: status
    integer :: n, solves
    real(wp) :: tol_f, tol_rate
    logical :: more

    n = size(mass)
    active = .false.
    stuck = .false.
    acceleration(1:n) = 0.0_wp
    status = lcp_too_large
    if (n > work%max_bodies .or. size(candidate) > work%max_rows) return
    tol_f = rel_tol * (sum(abs(force(1:n))) + 2.0_wp * sum(static_friction(1:n))) + tiny(1.0_wp)
    if (work%n_pairs > 0) tol_f = tol_f + rel_tol * 2.0_wp * sum(work%pair_static(1:work%n_pairs))
    tol_rate = rel_tol * sum(abs(rate(1:n)))
    work%broken(1:n) = .false.
    if (work%n_pairs > 0) work%pair_broken(1:work%n_pairs) = .false.
    do solves = 1, n + work%n_pairs + 1
      call build_lcp(work, mass, force, rate, friction, static_friction, velocity, row_body, row_normal, candidate)
      call lcp_solve(work%lcp, work%m(1:work%size, 1:work%size), work%q(1:work%size), work%z, work%w, &
        status, dq=work%dq(1:work%size))
      if (status /= lcp_solved) return
      call lcp_basis_values(work%lcp, work%dq(1:work%size), work%dz, work%dw)
      call accelerations(work, mass, rate, row_body, row_normal, candidate, acceleration)
      call break_away(work, mass, static_friction, velocity, acceleration, tol_f, tol_rate, more)
      if (work%n_pairs > 0) call pairs_break_away(work, mass, acceleration, tol_f, tol_rate, more)
      if (.not. more) exit
    end do
    call mode_of(work, mass, friction, velocity, size(candidate), acceleration, tol_f, tol_rate, &
      stuck, sgn, contact_force, friction_force)
    if (work%n_pairs > 0) call pairs_mode(work, mass, acceleration, tol_f, tol_rate)
    call hold_rows(work, mass, row_body, row_normal, candidate, contact_force, tol_f, tol_rate, &
      stuck, acceleration, active)
    status = cluster_solved
  end subroutine cluster_mode

  !> The LCP w = M z + q in z = (lambda_p over candidate rows, rho_r, mu_r over boxed
  !> bodies), every w an acceleration: w = (n_p.a, a_i + mu_i/m_i = a_i^+, (2 beta_i - rho_i)/m_i).
  subroutine build_lcp(work, mass, force, rate, friction, static_friction, velocity, row_body, row_normal, candidate)
    type(cluster_work_type), intent(inout) :: work
    real(wp), intent(in) :: mass(:), force(:), rate(:), friction(:), static_friction(:), velocity(:)
    integer, intent(in) :: row_body(:, :)
    real(wp), intent(in) :: row_normal(:, :)
    logical, intent(in) :: candidate(:)
    integer :: i, k, nc, nb, r, nbx

    nb = 0
    do i = 1, size(mass)
      work%slot(i) = 0
      work%beta(i) = 0.0_wp
      work%base(i) = force(i)
      if (velocity(i) /= 0.0_wp) then
        work%base(i) = force(i) - friction(i) * sign(1.0_wp, velocity(i))
        cycle
      end if
      if (static_friction(i) <= 0.0_wp) cycle
      work%beta(i) = merge(friction(i), static_friction(i), work%broken(i))
      if (work%beta(i) <= 0.0_wp) cycle           ! broken away without sliding friction: free
      work%base(i) = force(i) - work%beta(i)
      nb = nb + 1
      work%slot(i) = nb
    end do
    nbx = nb
    if (work%n_pairs > 0) call pair_slots(work, nbx)
    call row_coupling(mass, row_body, row_normal, candidate, work%row_var, nc, work%m)
    work%n_free_rows = nc
    work%n_boxed = nbx
    work%size = nc + 2 * nbx
    associate (m => work%m, s => work%size)
      m(nc + 1:s, 1:s) = 0.0_wp
      m(1:nc, nc + 1:s) = 0.0_wp
      work%q(1:s) = 0.0_wp
      work%dq(1:s) = 0.0_wp
      do k = 1, size(candidate)
        if (work%row_var(k) > 0) call add_row(work, k, mass, rate, row_body, row_normal)
      end do
      do i = 1, size(mass)
        r = work%slot(i)
        if (r == 0) cycle
        m(nc + r, nc + r) = 1.0_wp / mass(i)
        m(nc + r, nc + nbx + r) = 1.0_wp / mass(i)
        m(nc + nbx + r, nc + r) = -1.0_wp / mass(i)
        work%q(nc + r) = work%base(i) / mass(i)
        work%dq(nc + r) = rate(i) / mass(i)
        work%q(nc + nbx + r) = 2.0_wp * work%beta(i) / mass(i)
      end do
      do r = 1, work%n_pairs
        if (work%pair_slot(r) > 0) call add_pair(work, r, mass, rate, row_body, row_normal, size(candidate))
      end do
    end associate
  end subroutine build_lcp

  !> Candidate row k's coupling with its ends' boxes (n_k,i / m_i), its right-hand side
  !> n_k . M^-1 base and rate.
  subroutine add_row(work, k, mass, rate, row_body, row_normal)
    type(cluster_work_type), intent(inout) :: work
    integer, intent(in) :: k
    real(wp), intent(in) :: mass(:), rate(:)
    integer, intent(in) :: row_body(:, :)
    real(wp), intent(in) :: row_normal(:, :)
    integer :: p, e, i, box
    p = work%row_var(k)
    if (work%biased) then
      work%q(p) = work%q(p) + work%row_bias(k)
      work%dq(p) = work%dq(p) + work%row_bias_rate(k)
    end if
    do e = 1, 2
      i = row_body(e, k)
      if (i == 0) cycle
      work%q(p) = work%q(p) + row_normal(e, k) * (work%base(i) / mass(i))
      work%dq(p) = work%dq(p) + row_normal(e, k) * (rate(i) / mass(i))
      if (work%slot(i) == 0) cycle
      box = work%n_free_rows + work%slot(i)
      work%m(p, box) = row_normal(e, k) / mass(i)
      work%m(box, p) = row_normal(e, k) / mass(i)
    end do
  end subroutine add_row

  !> a = M^-1 (base + rho + N^T lambda) from the LCP's solution, and its rate da (work%da).
  subroutine accelerations(work, mass, rate, row_body, row_normal, candidate, acceleration)
    type(cluster_work_type), intent(inout) :: work
    real(wp), intent(in) :: mass(:), rate(:)
    integer, intent(in) :: row_body(:, :)
    real(wp), intent(in) :: row_normal(:, :)
    logical, intent(in) :: candidate(:)
    real(wp), intent(out) :: acceleration(:)
    integer :: i, k, e, p
    acceleration(1:size(mass)) = work%base(1:size(mass))
    work%da(1:size(mass)) = rate
    do i = 1, size(mass)
      if (work%slot(i) == 0) cycle
      acceleration(i) = acceleration(i) + work%z(work%n_free_rows + work%slot(i))
      work%da(i) = work%da(i) + work%dz(work%n_free_rows + work%slot(i))
    end do
    do k = 1, size(candidate)
      p = work%row_var(k)
      if (p == 0) cycle
      do e = 1, 2
        i = row_body(e, k)
        if (i == 0) cycle
        acceleration(i) = acceleration(i) + row_normal(e, k) * work%z(p)
        work%da(i) = work%da(i) + row_normal(e, k) * work%dz(p)
      end do
    end do
    do k = 1, work%n_pairs
      if (work%pair_slot(k) == 0) cycle
      p = work%n_free_rows + work%pair_slot(k)
      do e = 1, 2
        i = work%pair_body(e, k)
        acceleration(i) = acceleration(i) + pair_sign(e) * work%z(p)
        work%da(i) = work%da(i) + pair_sign(e) * work%dz(p)
      end do
    end do
    acceleration(1:size(mass)) = acceleration(1:size(mass)) / mass
    work%da(1:size(mass)) = work%da(1:size(mass)) / mass
  end subroutine accelerations

  !> Bodies at rest that the last solve moves (a or its rate not zero) break away: bound c
  !> from now on. more: some did (solve again).
  subroutine break_away(work, mass, static_friction, velocity, acceleration, tol_f, tol_rate, more)
    type(cluster_work_type), intent(inout) :: work
    real(wp), intent(in) :: mass(:), static_friction(:), velocity(:), acceleration(:), tol_f, tol_rate
    logical, intent(out) :: more
    integer :: i
    more = .false.
    do i = 1, size(mass)
      if (velocity(i) /= 0.0_wp .or. static_friction(i) <= 0.0_wp .or. work%broken(i)) cycle
      if (still(mass(i), acceleration(i), work%da(i), tol_f, tol_rate)) cycle
      work%broken(i) = .true.
      more = .true.
    end do
  end subroutine break_away

  !> Whether a body's acceleration a and its rate da are zero (in force units, within tol).
  pure logical function still(mass, a, da, tol_f, tol_rate)
    real(wp), intent(in) :: mass, a, da, tol_f, tol_rate
    still = abs(mass * a) <= tol_f .and. abs(mass * da) <= tol_rate
  end function still

  !> Stuck bodies, sliding directions and the forces of the final solve.
  subroutine mode_of(work, mass, friction, velocity, n_rows, acceleration, tol_f, tol_rate, &
      stuck, sgn, contact_force, friction_force)
    type(cluster_work_type), intent(in) :: work
    real(wp), intent(in) :: mass(:), friction(:), velocity(:), tol_f, tol_rate
    integer, intent(in) :: n_rows
    real(wp), intent(inout) :: acceleration(:)
    logical, intent(out) :: stuck(:)
    real(wp), intent(out) :: sgn(:), contact_force(:), friction_force(:)
    integer :: i, k
    do i = 1, size(mass)
      stuck(i) = .false.
      sgn(i) = 0.0_wp
      friction_force(i) = 0.0_wp
      if (velocity(i) /= 0.0_wp) then
        if (friction(i) > 0.0_wp) sgn(i) = sign(1.0_wp, velocity(i))
      else if (work%slot(i) > 0) then
        friction_force(i) = work%z(work%n_free_rows + work%slot(i)) - work%beta(i)
        if (still(mass(i), acceleration(i), work%da(i), tol_f, tol_rate)) then
          stuck(i) = .true.
          acceleration(i) = 0.0_wp
          cycle
        end if
        sgn(i) = sign(1.0_wp, acceleration(i))
        if (abs(mass(i) * acceleration(i)) <= tol_f) sgn(i) = sign(1.0_wp, work%da(i))
      else if (work%broken(i) .and. .not. still(mass(i), acceleration(i), work%da(i), tol_f, tol_rate)) then
        ! Broken away with no sliding friction (mu = 0 < mus): the way it leaves, as once it
        ! moves (as the two-body engine's modes gave it), so that its stop is watched and
        ! the mode just after the instant is this one, not one whose direction differs.
        sgn(i) = sign(1.0_wp, acceleration(i))
        if (abs(mass(i) * acceleration(i)) <= tol_f) sgn(i) = sign(1.0_wp, work%da(i))
      end if
      friction_force(i) = -friction(i) * sgn(i)
    end do
    ! Over the rows of this problem only: contact_force may be longer, and row_var beyond
    ! them holds an earlier problem's numbering.
    contact_force = 0.0_wp
    do k = 1, n_rows
      if (work%row_var(k) > 0) contact_force(k) = work%z(work%row_var(k))
    end do
  end subroutine mode_of

  !> The held rows (module header), and the exact common accelerations of the bodies they
  !> and the stuck bodies join.
  subroutine hold_rows(work, mass, row_body, row_normal, candidate, contact_force, tol_f, tol_rate, &
      stuck, acceleration, active)
    type(cluster_work_type), intent(inout) :: work
    real(wp), intent(in) :: mass(:), row_normal(:, :), contact_force(:), tol_f, tol_rate
    integer, intent(in) :: row_body(:, :)
    logical, intent(in) :: candidate(:), stuck(:)
    real(wp), intent(inout) :: acceleration(:)
    logical, intent(out) :: active(:)
    integer :: i, k, pass
    real(wp) :: dlambda
    logical :: joined
    do i = 0, size(mass)
      work%root(i) = i
    end do
    do i = 1, size(mass)
      if (stuck(i)) work%root(i) = 0
    end do
    do k = 1, work%n_pairs
      if (work%pair_stuck(k)) joined = uf_join(work%root, work%pair_body(1, k), work%pair_body(2, k))
    end do
    active = .false.
    do pass = 1, 2
      do k = 1, size(candidate)
        if (.not. candidate(k) .or. active(k)) cycle
        if (.not. closed(k)) cycle
        if (pass == 1) then
          dlambda = work%dz(work%row_var(k))
          if (contact_force(k) <= tol_f .and. (contact_force(k) < -tol_f .or. dlambda <= tol_rate)) cycle
          active(k) = .true.
          if (rigid_row(k)) joined = uf_join(work%root, row_body(1, k), row_body(2, k))
        else if (rigid_row(k)) then
          active(k) = uf_join(work%root, row_body(1, k), row_body(2, k))
        end if
      end do
    end do
    call group_means(work%root, mass, acceleration, work%group_mass, work%group_sum)

  contains

    !> Row k closed and staying closed: n.a and its rate zero (in the still frame: biased).
    logical function closed(k)
      integer, intent(in) :: k
      if (work%biased) then
        closed = row_closed(row_body, row_normal, k, mass, acceleration, work%da, tol_f, tol_rate, &
          work%row_bias(k), work%row_bias_rate(k))
      else
        closed = row_closed(row_body, row_normal, k, mass, acceleration, work%da, tol_f, tol_rate)
      end if
    end function closed

    !> A wall, or a body-body row of the form (-1, 1) or (1, -1): it makes its ends move alike.
    logical function rigid_row(k)
      integer, intent(in) :: k
      rigid_row = row_body(1, k) == 0 .or. row_body(2, k) == 0 .or. row_normal(1, k) == -row_normal(2, k)
    end function rigid_row
  end subroutine hold_rows

  !> The coefficient of end e (1: a, 2: b) of a friction contact on its relative coordinate
  !> x_b - x_a.
  pure real(wp) function pair_sign(e)
    integer, intent(in) :: e
    pair_sign = merge(-1.0_wp, 1.0_wp, e == 1)
  end function pair_sign

  !> The friction contacts' boxes (cluster_work_type), numbered after the bodies' (nbx: the
  !> boxes so far, then with the pairs'); each one's bound -beta on b and +beta on a moved
  !> into base, as a body's is.
  subroutine pair_slots(work, nbx)
    type(cluster_work_type), intent(inout) :: work
    integer, intent(inout) :: nbx
    integer :: p
    do p = 1, work%n_pairs
      work%pair_slot(p) = 0
      work%pair_beta(p) = merge(work%pair_slide(p), work%pair_static(p), work%pair_broken(p))
      if (work%pair_beta(p) <= 0.0_wp) cycle     ! no friction (left): free
      associate (ea => work%pair_body(1, p), eb => work%pair_body(2, p))
        work%base(ea) = work%base(ea) + work%pair_beta(p)
        work%base(eb) = work%base(eb) - work%pair_beta(p)
      end associate
      nbx = nbx + 1
      work%pair_slot(p) = nbx
    end do
  end subroutine pair_slots

  !> Friction contact p's box in the LCP (build_lcp's for a body, on J = e_b - e_a, D = J
  !> M^-1 J): its rows (J . a^+ and (2 beta - rho) D), and its coupling J M^-1 J' with the
  !> bodies' boxes, the other pairs' and the candidate rows that share an end.
  subroutine add_pair(work, p, mass, rate, row_body, row_normal, n_rows)
    type(cluster_work_type), intent(inout) :: work
    integer, intent(in) :: p, row_body(:, :), n_rows
    real(wp), intent(in) :: mass(:), rate(:), row_normal(:, :)
    integer :: nc, nbx, r, e, i, p2, k, v
    real(wp) :: d, coupling
    nc = work%n_free_rows
    nbx = (work%size - nc) / 2
    r = nc + work%pair_slot(p)
    d = 0.0_wp
    work%q(r) = 0.0_wp
    work%dq(r) = 0.0_wp
    do e = 1, 2
      i = work%pair_body(e, p)
      d = d + 1.0_wp / mass(i)
      work%q(r) = work%q(r) + pair_sign(e) * work%base(i) / mass(i)
      work%dq(r) = work%dq(r) + pair_sign(e) * rate(i) / mass(i)
      if (work%slot(i) > 0) then
        work%m(r, nc + work%slot(i)) = pair_sign(e) / mass(i)
        work%m(nc + work%slot(i), r) = pair_sign(e) / mass(i)
      end if
    end do
    work%m(r, r) = d
    work%m(r, r + nbx) = d
    work%m(r + nbx, r) = -d
    work%q(r + nbx) = 2.0_wp * work%pair_beta(p) * d
    do p2 = 1, work%n_pairs
      if (p2 == p .or. work%pair_slot(p2) == 0) cycle
      coupling = 0.0_wp
      do e = 1, 2
        do v = 1, 2
          i = work%pair_body(e, p)
          if (work%pair_body(v, p2) == i) coupling = coupling + pair_sign(e) * pair_sign(v) / mass(i)
        end do
      end do
      work%m(r, nc + work%pair_slot(p2)) = coupling
    end do
    do k = 1, n_rows
      if (work%row_var(k) == 0) cycle
      coupling = 0.0_wp
      do e = 1, 2
        do v = 1, 2
          i = work%pair_body(e, p)
          if (row_body(v, k) == i) coupling = coupling + pair_sign(e) * row_normal(v, k) / mass(i)
        end do
      end do
      work%m(r, work%row_var(k)) = coupling
      work%m(work%row_var(k), r) = coupling
    end do
  end subroutine add_pair

  !> Friction contacts at relative rest that the last solve moves apart (relative
  !> acceleration or its rate not zero) break away: bound pair_slide from now on. more: some did.
  subroutine pairs_break_away(work, mass, acceleration, tol_f, tol_rate, more)
    type(cluster_work_type), intent(inout) :: work
    real(wp), intent(in) :: mass(:), acceleration(:), tol_f, tol_rate
    logical, intent(inout) :: more
    integer :: p
    do p = 1, work%n_pairs
      if (work%pair_static(p) <= 0.0_wp .or. work%pair_broken(p)) cycle
      if (pair_still(work, p, mass, acceleration, tol_f, tol_rate)) cycle
      work%pair_broken(p) = .true.
      more = .true.
    end do
  end subroutine pairs_break_away

  !> Whether friction contact p's relative acceleration and its rate are zero (in force
  !> units of its reduced mass, within tol).
  logical function pair_still(work, p, mass, acceleration, tol_f, tol_rate)
    type(cluster_work_type), intent(in) :: work
    integer, intent(in) :: p
    real(wp), intent(in) :: mass(:), acceleration(:), tol_f, tol_rate
    associate (ea => work%pair_body(1, p), eb => work%pair_body(2, p))
      pair_still = still(1.0_wp / (1.0_wp / mass(ea) + 1.0_wp / mass(eb)), acceleration(eb) - acceleration(ea), &
        work%da(eb) - work%da(ea), tol_f, tol_rate)
    end associate
  end function pair_still

  !> The friction contacts' mode: stuck (their box holds the relative acceleration at 0), or
  !> the way the relative acceleration (its rate at a tie) goes.
  subroutine pairs_mode(work, mass, acceleration, tol_f, tol_rate)
    type(cluster_work_type), intent(inout) :: work
    real(wp), intent(in) :: mass(:), acceleration(:), tol_f, tol_rate
    integer :: p
    real(wp) :: rel
    do p = 1, work%n_pairs
      work%pair_stuck(p) = .false.
      work%pair_sgn(p) = 0.0_wp
      if (work%pair_static(p) <= 0.0_wp) cycle
      if (pair_still(work, p, mass, acceleration, tol_f, tol_rate)) then
        work%pair_stuck(p) = work%pair_slot(p) > 0
        cycle
      end if
      associate (ea => work%pair_body(1, p), eb => work%pair_body(2, p))
        rel = acceleration(eb) - acceleration(ea)
        work%pair_sgn(p) = sign(1.0_wp, rel)
        if (abs(rel) / (1.0_wp / mass(ea) + 1.0_wp / mass(eb)) <= tol_f) &
          work%pair_sgn(p) = sign(1.0_wp, work%da(eb) - work%da(ea))
      end associate
    end do
  end subroutine pairs_mode

end module impact1d_cluster_mode

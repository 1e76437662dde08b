!> The cluster mode solve (impact1d_cluster_mode) on closed forms with N bodies: a chain
!> pushed along the ground breaks away when the push exceeds sum s_i, a stack resting on the floor carries its weight, its top lifted off; and
!> random chains of 3 to 8 bodies checked against the conditions that define a mode.
program test_cluster_mode
  use impact1d_kinds, only: wp
  use impact1d_clusters, only: row_rate
  use impact1d_cluster_mode, only: cluster_work_type, cluster_reserve, cluster_mode, cluster_solved
  use testing, only: check, finish, seed_random
  implicit none
  integer, parameter :: max_n = 8
  type(cluster_work_type) :: work

  call seed_random(104729, 3)
  call cluster_reserve(work, max_n, 2 * max_n)

  call longer_outputs()
  call random_chains()
  call pushed_chain()
  call long_chain()
  call stack_on_floor()
  call finish('test_cluster_mode')

contains

  !> Output arrays longer than the problem's rows, after a problem with more rows: the rows
  !> beyond get no contact force (they read the earlier problem's numbering, and under
  !> MALLOC_PERTURB_ garbage, before this was fixed).
  subroutine longer_outputs()
    real(wp) :: a(2), sgn(2), lambda(4), ff(2)
    logical :: active(4), stuck(2)
    integer :: status
    integer, parameter :: body(2, 4) = reshape([0, 1, 1, 2, 1, 2, 0, 2], [2, 4])
    real(wp), parameter :: normal(2, 4) = reshape([0.0_wp, 1.0_wp, -1.0_wp, 1.0_wp, 1.0_wp, -1.0_wp, &
      0.0_wp, -1.0_wp], [2, 4])
    call cluster_mode(work, [1.0_wp, 1.0_wp], [-1.0_wp, 2.0_wp], [0.0_wp, 0.0_wp], [0.0_wp, 0.0_wp], &
      [0.0_wp, 0.0_wp], [0.0_wp, 0.0_wp], body, normal, [.true., .true., .true., .true.], a, active, stuck, &
      sgn, lambda, ff, status)
    lambda = 7.0_wp
    call cluster_mode(work, [1.0_wp, 1.0_wp], [-1.0_wp, 2.0_wp], [0.0_wp, 0.0_wp], [0.0_wp, 0.0_wp], &
      [0.0_wp, 0.0_wp], [0.0_wp, 0.0_wp], body(:, 1:1), normal(:, 1:1), [.true.], a, active, stuck, &
      sgn, lambda, ff, status)
    call check(status == cluster_solved .and. lambda(1) == 1.0_wp .and. all(lambda(2:4) == 0.0_wp) &
      .and. .not. any(active(2:4)), 'outputs longer than the rows: no force beyond them')
  end subroutine longer_outputs

  !> 5000 random chains of 3..8 bodies (both limits of each link now and then, walls at the
  !> ends, random candidates, bounds, forces, half the bodies at rest): the solution meets
  !> every condition of a mode to 1e-13 of the force scale: Newton's law with the reported
  !> forces, contact forces >= 0 and complementary to n.a >= 0, sliding friction against the
  !> motion, a stuck body at rest within its static bound, a body breaking away at c against
  !> its acceleration.
  subroutine random_chains()
    real(wp) :: mass(max_n), y(max_n), dy(max_n), c(max_n), s(max_n), v(max_n), a(max_n), sgn(max_n)
    real(wp) :: ff(max_n), lambda(2 * max_n), normal(2, 2 * max_n), u(8 * max_n), load(max_n), tol, worst, rate
    integer :: body(2, 2 * max_n), n, nr, k, e, trial, status, failed, moving
    logical :: candidate(2 * max_n), active(2 * max_n), stuck(max_n)
    worst = 0.0_wp
    failed = 0
    moving = 0
    do trial = 1, 5000
      call random_number(u)
      n = 3 + mod(trial, max_n - 2)
      mass(1:n) = 0.2_wp * 25.0_wp**u(1:n)
      c(1:n) = merge(0.0_wp, 3.0_wp * u(n + 1:2 * n), u(2 * n + 1:3 * n) < 0.2_wp)
      s(1:n) = c(1:n) * (1.0_wp + u(3 * n + 1:4 * n))
      y(1:n) = 16.0_wp * u(4 * n + 1:5 * n) - 8.0_wp
      dy(1:n) = 0.0_wp
      v(1:n) = merge(0.0_wp, sign(0.5_wp, u(5 * n + 1:6 * n) - 0.75_wp), u(5 * n + 1:6 * n) < 0.5_wp)
      nr = 0
      do k = 1, n - 1
        call add_row(body, normal, candidate, nr, [k, k + 1], [-1.0_wp, 1.0_wp], u(6 * n + k) < 0.8_wp)
        if (u(7 * n + k) < 0.2_wp) call add_row(body, normal, candidate, nr, [k, k + 1], [1.0_wp, -1.0_wp], u(6 * n + k) < 0.8_wp)
      end do
      call add_row(body, normal, candidate, nr, [0, 1], [0.0_wp, 1.0_wp], u(7 * n) < 0.5_wp)
      call add_row(body, normal, candidate, nr, [0, n], [0.0_wp, -1.0_wp], u(8 * n) < 0.5_wp)
      call cluster_mode(work, mass(1:n), y(1:n), dy(1:n), c(1:n), s(1:n), v(1:n), body(:, 1:nr), normal(:, 1:nr), &
        candidate(1:nr), a(1:n), active(1:nr), stuck(1:n), sgn(1:n), lambda(1:nr), ff(1:n), status)
      if (status /= cluster_solved) then
        failed = failed + 1
        cycle
      end if
      tol = sum(abs(y(1:n))) + 2.0_wp * sum(s(1:n))
      load(1:n) = y(1:n) + ff(1:n) - mass(1:n) * a(1:n)
      do k = 1, nr
        do e = 1, 2
          if (body(e, k) > 0) load(body(e, k)) = load(body(e, k)) + normal(e, k) * lambda(k)
        end do
        worst = max(worst, -lambda(k) / tol, merge(0.0_wp, abs(lambda(k)), candidate(k)) / tol)
        ! n_k . a in force units (times the lightest mass).
        rate = row_rate(body, normal, k, a) * minval(mass(1:n))
        if (candidate(k)) worst = max(worst, -rate / tol, min(lambda(k), abs(rate)) / tol)
      end do
      worst = max(worst, maxval(abs(load(1:n))) / tol)
      do k = 1, n
        if (v(k) /= 0.0_wp) then
          worst = max(worst, abs(ff(k) + c(k) * sign(1.0_wp, v(k))) / tol)
        else if (stuck(k)) then
          worst = max(worst, abs(a(k)), (abs(ff(k)) - s(k)) / tol)
        else if (s(k) > 0.0_wp) then
          moving = moving + 1
          worst = max(worst, abs(ff(k) + c(k) * sign(1.0_wp, a(k))) / tol, -a(k) * sgn(k) * mass(k) / tol)
        end if
      end do
    end do
    print '(a, es10.3, a, i0)', 'random chains: worst violation of a mode condition ', worst, &
      ', bodies breaking away ', moving
    call check(failed == 0 .and. worst <= 1.0e-13_wp .and. moving > 1000, 'random chains of 3-8 bodies: every mode condition')
  end subroutine random_chains

  !> Rows 1..n-1: block k touching block k + 1 (x_(k+1) - x_k >= its limit).
  subroutine neighbour_rows(body, normal, n)
    integer, intent(out) :: body(:, :)
    real(wp), intent(out) :: normal(:, :)
    integer, intent(in) :: n
    integer :: k
    do k = 1, n - 1
      body(:, k) = [k, k + 1]
      normal(:, k) = [-1.0_wp, 1.0_wp]
    end do
  end subroutine neighbour_rows

  !> One more row of a random chain.
  subroutine add_row(body, normal, candidate, nr, ends, coefficients, is_candidate)
    integer, intent(inout) :: body(:, :), nr
    real(wp), intent(inout) :: normal(:, :)
    logical, intent(inout) :: candidate(:)
    integer, intent(in) :: ends(2)
    real(wp), intent(in) :: coefficients(2)
    logical, intent(in) :: is_candidate
    nr = nr + 1
    body(:, nr) = ends
    normal(:, nr) = coefficients
    candidate(nr) = is_candidate
  end subroutine add_row

  !> N blocks in a row along the ground, touching (rows i, i+1 closed), pushed at block 1 by
  !> P towards block N: they stick while P <= sum s_i; beyond it they move as one with
  !> a = (P - sum c_i) / sum m_i, every contact held; exactly at sum s_i with P rising they
  !> break away now.
  subroutine pushed_chain()
    integer, parameter :: n = 6
    real(wp) :: mass(n), y(n), dy(n), c(n), s(n), v(n), a(n), sgn(n), ff(n), lambda(n - 1), normal(2, n - 1)
    integer :: body(2, n - 1), k, status
    logical :: active(n - 1), stuck(n)
    mass = [(real(k, wp), k = 1, n)]
    c = 0.5_wp * mass
    s = 0.75_wp * mass          ! sum s = 15.75, sum c = 10.5, sum m = 21
    v = 0.0_wp
    dy = 0.0_wp
    call neighbour_rows(body, normal, n)
    y = 0.0_wp
    y(1) = 15.0_wp
    call cluster_mode(work, mass, y, dy, c, s, v, body, normal, [(.true., k = 1, n - 1)], a, active, stuck, &
      sgn, lambda, ff, status)
    call check(status == cluster_solved .and. all(stuck) .and. all(a == 0.0_wp), 'chain pushed below sum s: stuck, a = 0')
    y(1) = 21.0_wp
    call cluster_mode(work, mass, y, dy, c, s, v, body, normal, [(.true., k = 1, n - 1)], a, active, stuck, &
      sgn, lambda, ff, status)
    call check(status == cluster_solved .and. .not. any(stuck) .and. all(active) .and. all(sgn == 1.0_wp) &
      .and. all(abs(a - 0.5_wp) <= 1.0e-15_wp) .and. all(a == a(1)), &
      'chain pushed above sum s: one body, a = (P - sum c) / sum m = 0.5, exactly alike')
    y(1) = 15.75_wp
    call cluster_mode(work, mass, y, dy, c, s, v, body, normal, [(.true., k = 1, n - 1)], a, active, stuck, &
      sgn, lambda, ff, status)
    call check(status == cluster_solved .and. all(stuck), 'chain pushed at exactly sum s, constant: stuck')
    dy(1) = 1.0_wp
    call cluster_mode(work, mass, y, dy, c, s, v, body, normal, [(.true., k = 1, n - 1)], a, active, stuck, &
      sgn, lambda, ff, status)
    call check(status == cluster_solved .and. .not. any(stuck) .and. all(abs(a - 0.25_wp) <= 1.0e-15_wp), &
      'chain pushed at exactly sum s and rising: breaks away, a = (15.75 - 10.5) / 21')
  end subroutine pushed_chain

  !> 40 unit blocks in a row (c = 0.5, s = 0.75 each: sum s = 30, sum c = 20), pushed at
  !> block 1: stuck under 30, one body at a = (40 - 20) / 40 under 40; frictionless against a
  !> wall at block 40, every contact carries the push. An LCP of 119 unknowns.
  subroutine long_chain()
    integer, parameter :: n = 40
    real(wp) :: mass(n), y(n), zero(n), c(n), s(n), a(n), sgn(n), ff(n), lambda(n), normal(2, n)
    integer :: body(2, n), k, status
    logical :: active(n), stuck(n)
    call cluster_reserve(work, n, 2 * n)
    mass = 1.0_wp
    c = 0.5_wp
    s = 0.75_wp
    zero = 0.0_wp
    call neighbour_rows(body, normal, n)
    y = 0.0_wp
    y(1) = 29.9_wp
    call cluster_mode(work, mass, y, zero, c, s, zero, body(:, 1:n - 1), normal(:, 1:n - 1), [(.true., k = 1, n - 1)], &
      a, active, stuck, sgn, lambda, ff, status)
    call check(status == cluster_solved .and. all(stuck) .and. all(a == 0.0_wp), '40 blocks pushed below sum s: stuck')
    y(1) = 40.0_wp
    call cluster_mode(work, mass, y, zero, c, s, zero, body(:, 1:n - 1), normal(:, 1:n - 1), [(.true., k = 1, n - 1)], &
      a, active, stuck, sgn, lambda, ff, status)
    call check(status == cluster_solved .and. .not. any(stuck) .and. all(active(1:n - 1)) .and. all(a == a(1)) &
      .and. abs(a(1) - 0.5_wp) <= 1.0e-14_wp, '40 blocks pushed above sum s: one body, a = 0.5')
    body(:, n) = [0, n]                    ! a wall to the right of block 40: x_wall - x_40 >= 0
    normal(:, n) = [0.0_wp, -1.0_wp]
    call cluster_mode(work, mass, y, zero, zero, zero, zero, body, normal, [(.true., k = 1, n)], &
      a, active, stuck, sgn, lambda, ff, status)
    call check(status == cluster_solved .and. all(active) .and. all(a == 0.0_wp) &
      .and. all(abs(lambda - 40.0_wp) <= 1.0e-12_wp), '40 frictionless blocks pushed into a wall: every contact carries 40')
  end subroutine long_chain

  !> A frictionless stack of N blocks on the floor under gravity (floor row 0-1, rows i, i+1):
  !> at rest, contact k carries the weight above it, g sum_{j >= k} m_j; a lift F > m_N g on
  !> the top block takes it off (a = (F - m_N g) / m_N) and leaves the rest held.
  subroutine stack_on_floor()
    integer, parameter :: n = 5
    real(wp), parameter :: g = 10.0_wp
    real(wp) :: mass(n), y(n), zero(n), a(n), sgn(n), ff(n), lambda(n), normal(2, n)
    integer :: body(2, n), k, status
    logical :: active(n), stuck(n)
    mass = [2.0_wp, 1.0_wp, 4.0_wp, 0.5_wp, 1.5_wp]
    zero = 0.0_wp
    y = -g * mass
    body(:, 1) = [0, 1]
    normal(:, 1) = [0.0_wp, 1.0_wp]
    do k = 2, n
      body(:, k) = [k - 1, k]
      normal(:, k) = [-1.0_wp, 1.0_wp]
    end do
    call cluster_mode(work, mass, y, zero, zero, zero, zero, body, normal, [(.true., k = 1, n)], a, active, stuck, &
      sgn, lambda, ff, status)
    call check(status == cluster_solved .and. all(active) .and. all(a == 0.0_wp), 'stack on the floor: held, a = 0')
    call check(all([(abs(lambda(k) - g * sum(mass(k:n))) <= 1.0e-13_wp * g * sum(mass), k = 1, n)]), &
      'stack on the floor: contact k carries the weight above it')
    y(n) = y(n) + 20.0_wp
    call cluster_mode(work, mass, y, zero, zero, zero, zero, body, normal, [(.true., k = 1, n)], a, active, stuck, &
      sgn, lambda, ff, status)
    call check(status == cluster_solved .and. all(active(1:n - 1)) .and. .not. active(n) .and. all(a(1:n - 1) == 0.0_wp) &
      .and. abs(a(n) - (20.0_wp - g * mass(n)) / mass(n)) <= 1.0e-14_wp, 'stack: the top block lifted off, the rest held')
  end subroutine stack_on_floor
end program test_cluster_mode

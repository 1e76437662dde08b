!> The joint inelastic impact of a cluster (impact1d_cluster_impact): random two-body impacts
!> against impact1d_impacts' inelastic_projection; random chains of N bodies checked as a
!> projection (no closed row approaches, impulses >= 0 and complementary, kinetic energy not
!> gained); and the answers of tests/exact_nbody.py on a stack driven into a wall, a
!> cradle-like chain struck at one end and a chain whose far end leaves.
program test_cluster_impact
  use impact1d_kinds, only: wp
  use impact1d_scene, only: scene_type
  use impact1d_impacts, only: inelastic_projection
  use impact1d_modes, only: pair_rows
  use impact1d_lcp, only: lcp_solved
  use impact1d_clusters, only: row_rate
  use impact1d_cluster_impact, only: impact_work_type, impact_reserve, cluster_projection
  use testing, only: check, finish, two_body, seed_random
  implicit none
  integer, parameter :: max_n = 8
  !> The two-body scene's rows on their ends: left (0, 1), right (0, 2), slot_min, slot_max.
  integer, parameter :: pair_body(2, 4) = reshape([0, 1, 0, 2, 1, 2, 1, 2], [2, 4])
  real(wp), parameter :: pair_normal(2, 4) = reshape([0.0_wp, 1.0_wp, 0.0_wp, -1.0_wp, -1.0_wp, 1.0_wp, &
    1.0_wp, -1.0_wp], [2, 4])
  type(impact_work_type) :: work

  call seed_random(7177, 5)
  call impact_reserve(work, max_n, 2 * max_n)
  call against_two_body()
  call random_chains()
  call exact_nbody_answers()
  call finish('test_cluster_impact')

contains

  !> 2000 random impacts of two bodies (masses 0.2..5, velocities -5..5, a random set of the
  !> four rows closed): the same velocities after as inelastic_projection, to 1e-13 of |v|,
  !> and the same rows pushed where no closed row is left at rest without an impulse.
  subroutine against_two_body()
    type(scene_type) :: scene
    real(wp) :: u(8), v(2), mine(2), theirs(2), impulse(4), worst
    logical :: closed(4), pushed(4), their_pushed(4), closed_rows(pair_rows), pushed_rows(pair_rows)
    real(wp) :: rounding_rows(pair_rows)
    character(len=200) :: assignments
    integer :: trial, status, failed, strict, same
    ! The engine's rounding level of a normal velocity of about 10 m/s (64 ulps of it): with
    ! none, inelastic_projection refuses its own answer when rounding leaves it 1e-16 m/s apart.
    real(wp), parameter :: u_rounding(4) = 64.0_wp * epsilon(1.0_wp) * 10.0_wp
    worst = 0.0_wp
    failed = 0
    strict = 0
    same = 0
    do trial = 1, 2000
      call random_number(u)
      write(assignments, '(a, es23.16, a, es23.16, a)') 'm1 = ', 0.2_wp * 25.0_wp**u(1), ', m2 = ', &
        0.2_wp * 25.0_wp**u(2), ', x_left = -1, x_right = 5, d_min = 0.5, d_max = 2'
      call two_body(trim(assignments), scene)
      v = 10.0_wp * u(3:4) - 5.0_wp
      closed = u(5:8) < 0.6_wp
      ! inelastic_projection's arrays are pair_rows long: the scene's four rows first.
      closed_rows = .false.
      closed_rows(1:4) = closed
      rounding_rows = 0.0_wp
      rounding_rows(1:4) = u_rounding
      call inelastic_projection(scene, closed_rows, v, rounding_rows, theirs, pushed_rows)
      their_pushed = pushed_rows(1:4)
      call cluster_projection(work, scene%pair%mass, v, pair_body, pair_normal, closed, u_rounding, mine, impulse, &
        pushed, status)
      if (status /= lcp_solved) failed = failed + 1
      worst = max(worst, maxval(abs(mine - theirs)) / maxval(abs(v)))
      if (maxval(abs(mine - theirs)) > 1.0e-13_wp * maxval(abs(v)) .and. failed < 5) then
        failed = failed + 1
        print '(a, i0, a, 2es12.4, a, 2es12.4, a, 4l2, a, 2es12.4, a, 2es12.4)', 'trial ', trial, ' m', scene%pair%mass, &
          ' v', v, ' closed', closed, ' LCP', mine, ' enumerator', theirs
      end if
      if (any(closed .and. pushed) .and. all(.not. closed .or. impulse > 1.0e-9_wp .or. &
          matmul(mine, pair_rates()) > 1.0e-9_wp)) then
        strict = strict + 1
        if (all(pushed .eqv. their_pushed)) same = same + 1
      end if
    end do
    print '(a, es10.3, a, i0, a, i0)', 'two-body impacts: worst |w - w_enum| / |v| ', worst, &
      ', pushed rows unique in ', strict, ', the same in ', same
    call check(failed == 0 .and. worst <= 1.0e-13_wp, 'random two-body impacts: the projection of impacts.f90')
    call check(strict > 200 .and. same == strict, 'random two-body impacts: the same rows pushed where unique')
  end subroutine against_two_body

  !> The pair's rows' normals on the two bodies, as columns: u . pair_rates() = the rows' rates.
  pure function pair_rates() result(rates)
    real(wp) :: rates(2, 4)
    rates = reshape([1.0_wp, 0.0_wp, 0.0_wp, -1.0_wp, -1.0_wp, 1.0_wp, 1.0_wp, -1.0_wp], [2, 4])
  end function pair_rates

  !> 2000 random chains of 3..8 bodies (rows between neighbours, a wall at either end now and
  !> then, some rows closed): a projection.
  subroutine random_chains()
    real(wp) :: mass(max_n), v(max_n), w(max_n), normal(2, max_n + 1), impulse(max_n + 1), tol(max_n + 1)
    real(wp) :: u(3 * max_n), ke_before, ke_after, worst, scale, nw
    integer :: body(2, max_n + 1), n, nr, k, trial, status, failed, several
    logical :: closed(max_n + 1), pushed(max_n + 1)
    worst = 0.0_wp
    failed = 0
    several = 0
    tol = 0.0_wp
    do trial = 1, 2000
      call random_number(u)
      n = 3 + mod(trial, max_n - 2)
      mass(1:n) = 0.2_wp * 25.0_wp**u(1:n)
      v(1:n) = 10.0_wp * u(n + 1:2 * n) - 5.0_wp
      do k = 1, n - 1
        body(:, k) = [k, k + 1]
        normal(:, k) = [-1.0_wp, 1.0_wp]
      end do
      body(:, n) = [0, 1]                             ! a wall on the left of body 1
      normal(:, n) = [0.0_wp, 1.0_wp]
      body(:, n + 1) = [0, n]                         ! and on the right of body n
      normal(:, n + 1) = [0.0_wp, -1.0_wp]
      nr = n + 1
      closed(1:nr) = u(2 * n + 1:3 * n + 1) < 0.7_wp
      call cluster_projection(work, mass(1:n), v(1:n), body(:, 1:nr), normal(:, 1:nr), closed(1:nr), tol(1:nr), &
        w(1:n), impulse(1:nr), pushed(1:nr), status)
      if (status /= lcp_solved) failed = failed + 1
      if (count(pushed(1:nr)) >= 2) several = several + 1
      ke_before = sum(mass(1:n) * v(1:n)**2)
      ke_after = sum(mass(1:n) * w(1:n)**2)
      scale = maxval(abs(v(1:n)))
      worst = max(worst, (ke_after - ke_before) / ke_before)
      do k = 1, nr
        if (.not. closed(k)) cycle
        nw = row_rate(body, normal, k, w)
        worst = max(worst, -nw / scale, -impulse(k) / (scale * maxval(mass(1:n))), &
          min(impulse(k) / maxval(mass(1:n)), abs(nw)) / scale)
      end do
    end do
    print '(a, es10.3, a, i0)', 'chains: worst violation (feasibility, sign, complementarity, energy) ', worst, &
      ', impacts on two rows or more ', several
    call check(failed == 0 .and. worst <= 1.0e-13_wp .and. several > 500, 'random chains: the inelastic projection')
  end subroutine random_chains

  !> tests/exact_nbody.py's answers (its joint projection at t = 0 of the same scenes).
  subroutine exact_nbody_answers()
    real(wp) :: w(4), impulse(4), tol(4)
    integer :: body(2, 4), status, k
    logical :: pushed(4)
    real(wp) :: normal(2, 4)
    tol = 0.0_wp
    do k = 1, 3
      body(:, k) = [k, k + 1]
      normal(:, k) = [-1.0_wp, 1.0_wp]
    end do
    body(:, 4) = [0, 1]
    normal(:, 4) = [0.0_wp, 1.0_wp]
    ! Unit masses touching, body 1 leaving at -1, body 4 driven in at -2: bodies 2-4 merge at
    ! -2/3, body 1 leaves (exact_nbody: c2, c3 pushed, velocities (-1, -2/3, -2/3, -2/3)).
    call cluster_projection(work, [1.0_wp, 1.0_wp, 1.0_wp, 1.0_wp], [-1.0_wp, 0.0_wp, 0.0_wp, -2.0_wp], &
      body(:, 1:3), normal(:, 1:3), [.true., .true., .true.], tol(1:3), w, impulse(1:3), pushed(1:3), status)
    call check(status == lcp_solved .and. w(1) == -1.0_wp .and. all(abs(w(2:4) + 2.0_wp / 3.0_wp) <= 1.0e-15_wp) &
      .and. all(w(2:4) == w(2)) .and. all(pushed(1:3) .eqv. [.false., .true., .true.]), &
      'chain, far end leaving: (-1, -2/3, -2/3, -2/3), two rows pushed')
    ! Masses 2, 1, 3, 0.5 touching, body 1 strikes at 1.5: all at 3/6.5 (exact_nbody: 0.461538...).
    call cluster_projection(work, [2.0_wp, 1.0_wp, 3.0_wp, 0.5_wp], [1.5_wp, 0.0_wp, 0.0_wp, 0.0_wp], &
      body(:, 1:3), normal(:, 1:3), [.true., .true., .true.], tol(1:3), w, impulse(1:3), pushed(1:3), status)
    call check(status == lcp_solved .and. all(abs(w - 3.0_wp / 6.5_wp) <= 1.0e-15_wp) .and. all(w == w(1)) &
      .and. all(pushed(1:3)), 'struck chain: one common velocity, momentum kept, every row pushed')
    ! The same chain on a wall, driven in at its far end: everything stops, every row pushed.
    call cluster_projection(work, [2.0_wp, 1.0_wp, 3.0_wp, 0.5_wp], [0.0_wp, 0.0_wp, 0.0_wp, -2.0_wp], &
      body, normal, [.true., .true., .true., .true.], tol, w, impulse, pushed, status)
    call check(status == lcp_solved .and. all(w == 0.0_wp) .and. all(pushed), 'stack driven into a wall: all stop exactly')
  end subroutine exact_nbody_answers
end program test_cluster_impact

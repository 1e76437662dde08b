!> The joint inelastic impact of a cluster (impact1d_cluster_impact): random chains of N
!> bodies checked as a projection (no closed row approaches, impulses >= 0 and complementary, kinetic energy not
!> gained); and the answers of tests/exact_nbody.py on a stack driven into a wall, a
!> cradle-like chain struck at one end and a chain whose far end leaves.
program test_cluster_impact
  use impact1d_kinds, only: wp
  use impact1d_lcp, only: lcp_solved
  use impact1d_clusters, only: row_rate
  use impact1d_cluster_impact, only: impact_work_type, impact_reserve, cluster_projection
  use testing, only: check, finish, seed_random
  implicit none
  integer, parameter :: max_n = 8
  type(impact_work_type) :: work

  call seed_random(7177, 5)
  call impact_reserve(work, max_n, 2 * max_n)
  call random_chains()
  call exact_nbody_answers()
  call finish('test_cluster_impact')

contains

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

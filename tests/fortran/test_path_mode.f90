!> The path solve (impact1d_path_mode) against the dense one (impact1d_cluster_mode's LCP and
!> impact1d_body_mode's preference for friction), both through impact1d_body_mode's
!> gathered_mode: on random clusters whose rows form a path (bodies and rows numbered at
!> random, a wall at either end or none, bodies at rest and sliding, forces, rates, bounds and
!> masses drawn from few values so that ties are common), the same mode: held rows, stuck
!> bodies, sliding directions. And clusters that are not paths (a body in three rows, rows
!> ordering the path both ways) are left to the dense solve.
!> The joint inelastic impact of such paths (impact1d_path_impact) against the dense
!> projection (impact1d_cluster_impact) on random paths whose order turns at most once (a
!> train taking up a coupler: taut couplers, the standing part's buffers): the same velocities
!> after and the same rows pushed; paths turning twice are left to the dense projection.
program test_path_mode
  use impact1d_kinds, only: wp
  use impact1d_body_mode, only: mode_work_type, mode_reserve, gathered_mode, mode_solved
  use impact1d_path_mode, only: path_order, path_mode
  use impact1d_path_impact, only: path_impact_work_type, path_impact_reserve, path_projection
  use impact1d_cluster_impact, only: impact_work_type, impact_reserve, cluster_projection
  use impact1d_lcp, only: lcp_solved
  use testing, only: check, finish, seed_random
  implicit none
  integer, parameter :: max_n = 12, trials = 40000
  type(mode_work_type) :: work
  integer :: trial

  call seed_random(7919, 11)
  call mode_reserve(work, max_n, max_n + 1)
  call compare_random(.false.)
  call compare_random(.true.)
  call seed_clusters()
  call not_paths()
  call rising_into_a_stuck_body()
  call projections()
  call take_up()
  call finish('test_path_mode')

contains

  !> The path solve against the dense one on random paths (program header); resting: most
  !> bodies at rest, unloaded and frictionless or with static friction only (mu = 0 < mus),
  !> so that force-free rows, frictionless bodies resting on stuck ones and break-aways with
  !> no sliding friction are common.
  subroutine compare_random(resting)
    logical, intent(in) :: resting
    integer :: trial, n, nr, status, differ, shown, paths, motion
    logical :: stuck(max_n), active(max_n + 1), same
    real(wp) :: sgn(max_n)
    differ = 0
    shown = 0
    paths = 0
    motion = 0
    do trial = 1, trials
      call random_path(n, nr, resting)
      if (path_order(work%path, n, work%row_body(:, 1:nr), work%row_normal(:, 1:nr))) paths = paths + 1
      work%dense_only = .true.
      call gathered_mode(work, n, nr, status)
      if (status /= mode_solved) cycle
      stuck(1:n) = work%stuck(1:n)
      sgn(1:n) = work%sgn(1:n)
      active(1:nr) = work%active(1:nr)
      call path_solve(n, nr, status)
      same = status == mode_solved .and. all(stuck(1:n) .eqv. work%stuck(1:n)) .and. all(sgn(1:n) == work%sgn(1:n)) &
        .and. all(active(1:nr) .eqv. work%active(1:nr))
      if (.not. (all(stuck(1:n) .eqv. work%stuck(1:n)) .and. all(sgn(1:n) == work%sgn(1:n)))) motion = motion + 1
      if (.not. same) then
        differ = differ + 1
        if (shown < 5) call show(n, nr, stuck, sgn, active)
        shown = shown + 1
      end if
    end do
    print '(a, l2, a, i0, a, i0, a, i0, a, i0)', 'random paths (resting', resting, '): ', trials, ', accepted as paths ', &
      paths, ', modes differing ', differ, ', in motion ', motion
    call check(paths == trials, 'every random path is taken by the path solve')
    call check(differ == 0, 'the path solve finds the dense solve''s mode')
  end subroutine compare_random

  !> A random cluster along a path (program header, compare_random) in work's gathered arrays.
  subroutine random_path(n, nr, resting)
    integer, intent(out) :: n, nr
    logical, intent(in) :: resting
    integer :: perm(max_n), row_of(max_n + 1), t, i, k, wall_end
    real(wp) :: s, r
    n = 1 + int(rand() * max_n)
    call shuffle(perm, n)
    s = merge(1.0_wp, -1.0_wp, rand() < 0.5_wp)
    wall_end = int(rand() * 3.0_wp)         ! 0 none, 1 before p_1, 2 after p_n
    nr = n - 1 + merge(0, 1, wall_end == 0)
    call shuffle(row_of, nr)
    do t = 1, n - 1
      k = row_of(t)
      ! The row says s (a(p_(t+1)) - a(p_t)) >= 0, written from either end.
      if (rand() < 0.5_wp) then
        work%row_body(:, k) = [perm(t), perm(t + 1)]
        work%row_normal(:, k) = [-s, s]
      else
        work%row_body(:, k) = [perm(t + 1), perm(t)]
        work%row_normal(:, k) = [s, -s]
      end if
    end do
    if (wall_end > 0) then
      k = row_of(nr)
      work%row_body(:, k) = [0, merge(perm(1), perm(n), wall_end == 1)]
      work%row_normal(:, k) = [0.0_wp, merge(s, -s, wall_end == 1)]
    end if
    do i = 1, n
      work%mass(i) = pick([1.0_wp, 2.0_wp, 0.5_wp, 1.0_wp + rand()])
      work%force(i) = pick([0.0_wp, 1.0_wp, -1.0_wp, 2.0_wp, -3.0_wp, 4.0_wp * rand() - 2.0_wp])
      work%rate(i) = pick([0.0_wp, 0.0_wp, 1.0_wp, -1.0_wp])
      work%friction(i) = pick([0.0_wp, 1.0_wp, 0.5_wp, 2.0_wp])
      work%static(i) = work%friction(i) + pick([0.0_wp, 0.5_wp, 1.0_wp])
      r = rand()
      work%velocity(i) = 0.0_wp
      if (r < 0.2_wp) work%velocity(i) = 1.0_wp
      if (r >= 0.2_wp .and. r < 0.35_wp) work%velocity(i) = -2.0_wp
      if (.not. resting) cycle
      work%force(i) = pick([0.0_wp, 0.0_wp, 0.0_wp, 1.0_wp, -1.0_wp, 4.0_wp * rand() - 2.0_wp])
      work%rate(i) = pick([0.0_wp, 0.0_wp, 1.0_wp, -1.0_wp])
      work%friction(i) = pick([0.0_wp, 0.0_wp, 1.0_wp])
      work%static(i) = work%friction(i) + pick([0.0_wp, 0.5_wp, 2.0_wp])
      if (r >= 0.1_wp) work%velocity(i) = 0.0_wp
    end do
  end subroutine random_path

  !> Clusters met by tests/test_nbody_stress.py's random scenes, where the path solve once
  !> lacked the dense solve's rules: a frictionless body (1) resting on a body stuck on the
  !> right wall keeps its force-free row (random_scene 82), and a body with static but no
  !> sliding friction (1) pulled away by the body it is coupled to breaks away in the way it
  !> leaves (random_scene 49 with force tables).
  subroutine seed_clusters()
    integer :: status
    logical :: dense_active(2), dense_stuck(2)
    real(wp) :: dense_sgn(2)
    work%mass(1:2) = [2.5625_wp, 0.953125_wp]
    work%force(1:2) = 0.0_wp
    work%rate(1:2) = 0.0_wp
    work%friction(1:2) = [0.0_wp, 2.338134765625_wp]
    work%static(1:2) = [0.0_wp, 4.09173583984375_wp]
    work%velocity(1:2) = 0.0_wp
    work%row_body(:, 1:2) = reshape([1, 2, 0, 2], [2, 2])
    work%row_normal(:, 1:2) = reshape([-1.0_wp, 1.0_wp, 0.0_wp, -1.0_wp], [2, 2])
    work%dense_only = .true.
    call gathered_mode(work, 2, 2, status)
    dense_active = work%active(1:2)
    call path_solve(2, 2, status)
    call check(status == mode_solved .and. work%stuck(2) .and. work%active(1) .and. .not. work%active(2) .and. &
      all(dense_active .eqv. work%active(1:2)), 'random_scene 82: a frictionless body keeps its row to a stuck one')
    work%mass(1:2) = [1.3125_wp, 1.890625_wp]
    work%force(1:2) = [8.27507246682375808_wp, 2.59509418081828258_wp]
    work%rate(1:2) = [-4.625_wp, 22.0192307692307701_wp]
    work%friction(1:2) = [0.0_wp, 3.7683258056640625_wp]
    work%static(1:2) = [1.00616455078125_wp, 6.377166748046875_wp]
    work%velocity(1:2) = 0.0_wp
    work%row_body(:, 1) = [1, 2]
    work%row_normal(:, 1) = [-1.0_wp, 1.0_wp]
    work%dense_only = .true.
    call gathered_mode(work, 2, 1, status)
    dense_stuck = work%stuck(1:2)
    dense_sgn = work%sgn(1:2)
    call path_solve(2, 1, status)
    call check(status == mode_solved .and. .not. any(work%stuck(1:2)) .and. all(work%sgn(1:2) == 1.0_wp) .and. &
      all(dense_sgn == work%sgn(1:2)) .and. all(dense_stuck .eqv. work%stuck(1:2)), &
      'random_scene 49 with tables: a mu = 0 < mus body breaks away in the way it leaves')
  end subroutine seed_clusters

  !> The dense solve's preference for friction lets a held row go only if the motion stays
  !> the same, rates included: a free body at rest whose force is rising (body 2) against a
  !> stuck one (body 1) keeps the row between them held (it let it go when it compared the
  !> accelerations only, and the bodies then closed into the row at the rate).
  subroutine rising_into_a_stuck_body()
    integer :: status
    work%mass(1:3) = [0.5_wp, 2.0_wp, 1.0_wp]
    work%force(1:3) = [0.0_wp, 0.0_wp, 1.0_wp]
    work%rate(1:3) = [-1.0_wp, 1.0_wp, -1.0_wp]
    work%friction(1:3) = [1.0_wp, 0.0_wp, 1.0_wp]
    work%static(1:3) = [1.5_wp, 0.0_wp, 2.0_wp]
    work%velocity(1:3) = 0.0_wp
    work%row_body(:, 1:3) = reshape([1, 3, 1, 2, 0, 3], [2, 3])
    work%row_normal(:, 1:3) = reshape([-1.0_wp, 1.0_wp, 1.0_wp, -1.0_wp, 0.0_wp, -1.0_wp], [2, 3])
    work%dense_only = .true.
    call gathered_mode(work, 3, 3, status)
    call check(status == mode_solved .and. work%stuck(1) .and. .not. work%stuck(2) .and. work%active(2), &
      'the dense solve holds a row a free body rises into')
    call path_solve(3, 3, status)
    call check(status == mode_solved .and. work%active(2), 'so does the path solve')
  end subroutine rising_into_a_stuck_body

  !> The gathered problem of n bodies and nr rows solved by the path solve (status:
  !> mode_solved, or -1 when the rows do not form a path it takes).
  subroutine path_solve(n, nr, status)
    integer, intent(in) :: n, nr
    integer, intent(out) :: status
    status = -1
    if (.not. path_order(work%path, n, work%row_body(:, 1:nr), work%row_normal(:, 1:nr))) return
    call path_mode(work%path, work%mass(1:n), work%force(1:n), work%rate(1:n), work%friction(1:n), &
      work%static(1:n), work%velocity(1:n), work%row_body(:, 1:nr), work%row_normal(:, 1:nr), &
      work%acc(1:n), work%acc_rate(1:n), work%active(1:nr), work%stuck(1:n), work%sgn(1:n))
    status = mode_solved
  end subroutine path_solve

  !> Random paths (program header) struck: the path projection against the dense one.
  subroutine projections()
    type(path_impact_work_type) :: path_work
    type(impact_work_type) :: dense_work
    integer, parameter :: tries = 20000
    integer :: perm(max_n), row_of(max_n + 1), t, k, i, n, nr, turn, wall_end, fitted, differ, status
    real(wp) :: s, c, row_normal(2, max_n + 1), mass(max_n), v(max_n), tol(max_n + 1), v_path(max_n), &
      v_dense(max_n), p_path(max_n + 1), p_dense(max_n + 1), scale
    integer :: row_body(2, max_n + 1)
    logical :: pushed_path(max_n + 1), pushed_dense(max_n + 1), fits, turned_twice
    call path_impact_reserve(path_work, max_n)
    call impact_reserve(dense_work, max_n, max_n + 1)
    fitted = 0
    differ = 0
    do trial = 1, tries
      n = 1 + int(rand() * max_n)
      call shuffle(perm, n)
      s = merge(1.0_wp, -1.0_wp, rand() < 0.5_wp)
      ! The order turns at position turn (none if turn >= n), twice now and then.
      turn = 2 + int(rand() * n)
      turned_twice = rand() < 0.1_wp .and. turn + 1 < n
      wall_end = int(rand() * 3.0_wp)
      nr = n - 1 + merge(0, 1, wall_end == 0)
      call shuffle(row_of, nr)
      do t = 1, n - 1
        k = row_of(t)
        c = s
        if (t >= turn) c = -s
        if (turned_twice .and. t >= turn + 1) c = s
        if (rand() < 0.5_wp) then
          row_body(:, k) = [perm(t), perm(t + 1)]
          row_normal(:, k) = [-c, c]
        else
          row_body(:, k) = [perm(t + 1), perm(t)]
          row_normal(:, k) = [c, -c]
        end if
      end do
      if (wall_end > 0) then
        k = row_of(nr)
        c = merge(s, -s, rand() < 0.8_wp)
        row_body(:, k) = [0, merge(perm(1), perm(n), wall_end == 1)]
        row_normal(:, k) = [0.0_wp, c]
      end if
      do i = 1, n
        mass(i) = pick([1.0_wp, 2.0_wp, 40.0_wp, 80.0_wp, 1.0_wp + rand()])
        v(i) = pick([0.0_wp, 0.0_wp, 1.0_wp, -1.0_wp, 0.5_wp, 4.0_wp * rand() - 2.0_wp])
      end do
      tol(1:nr) = 1.0e-12_wp
      call path_projection(path_work, mass(1:n), v(1:n), row_body(:, 1:nr), row_normal(:, 1:nr), tol(1:nr), &
        v_path(1:n), p_path(1:nr), pushed_path(1:nr), fits)
      if (turned_twice) call check(.not. fits, 'a path turning twice is left to the dense projection')
      if (.not. fits) cycle
      fitted = fitted + 1
      call cluster_projection(dense_work, mass(1:n), v(1:n), row_body(:, 1:nr), row_normal(:, 1:nr), &
        spread(.true., 1, nr), tol(1:nr), v_dense(1:n), p_dense(1:nr), pushed_dense(1:nr), status)
      scale = maxval(abs(v(1:n))) + 1.0_wp
      if (status /= lcp_solved .or. any(abs(v_path(1:n) - v_dense(1:n)) > 1.0e-13_wp * scale) .or. &
          any(pushed_path(1:nr) .neqv. pushed_dense(1:nr))) then
        differ = differ + 1
        if (differ <= 3) then
          print '(a, i0, a, i0)', 'projection differs: n = ', n, ' rows = ', nr
          print '(a, 12f9.4)', ' mass ', mass(1:n)
          print '(a, 12f9.4)', ' v    ', v(1:n)
          print '(a, 12f9.4)', ' path ', v_path(1:n)
          print '(a, 12f9.4)', ' dense', v_dense(1:n)
          print '(a, 13f9.4)', ' P path ', p_path(1:nr)
          print '(a, 13f9.4)', ' P dense', p_dense(1:nr)
          do k = 1, nr
            print '(a, 2i4, 2f5.1, 2l2)', ' row', row_body(:, k), row_normal(:, k), pushed_path(k), pushed_dense(k)
          end do
        end if
      end if
    end do
    print '(a, i0, a, i0, a, i0)', 'random impacts: ', tries, ', taken as paths ', fitted, ', differing ', differ
    call check(fitted > tries / 2, 'most random impacts along a path turning at most once are taken')
    call check(differ == 0, 'the path projection is the dense one')
  end subroutine projections

  !> A train of 2000 wagons takes up the coupler of a wagon: the moving part (taut couplers)
  !> and the standing part (buffers closed) are one group; 400 take-ups, the moving part
  !> growing. The standing part's buffers take no impulse and its wagons stay at rest
  !> (summed from the moving part's end, the impulses' rounding once reached every buffer
  !> as the same tiny push, and the whole train was joined at one velocity).
  subroutine take_up()
    integer, parameter :: n = 2000
    type(path_impact_work_type) :: path_work
    integer, allocatable :: row_body(:, :)
    real(wp), allocatable :: row_normal(:, :), mass(:), v(:), tol(:), v_after(:), impulse(:)
    logical, allocatable :: pushed(:)
    logical :: fits, ok
    integer :: i, picked
    allocate(row_body(2, n - 1), row_normal(2, n - 1), mass(n), v(n), tol(n - 1), v_after(n), impulse(n - 1), &
      pushed(n - 1))
    call path_impact_reserve(path_work, n)
    mass = 40.0_wp
    mass(n) = 80.0_wp
    tol = 1.0e-12_wp
    ok = .true.
    ! The moving part grown wagon by wagon, its speed that of a take-up series.
    do picked = n - 1, n - 400, -1
      v = 0.0_wp
      v(picked + 1:) = 17.735625006869562_wp * (1.0_wp + 0.37_wp * (n - picked) / 400.0_wp)
      do i = 1, n - 1
        row_body(:, i) = [i, i + 1]
        row_normal(:, i) = merge([-1.0_wp, 1.0_wp], [1.0_wp, -1.0_wp], i < picked)   ! buffers, then couplers
      end do
      call path_projection(path_work, mass, v, row_body, row_normal, tol, v_after, impulse, pushed, fits)
      ok = ok .and. fits .and. all(v_after(1:picked - 1) == 0.0_wp) .and. .not. any(pushed(1:picked - 1)) .and. &
        all(v_after(picked:) == v_after(n)) .and. all(pushed(picked:))
    end do
    call check(ok, 'a take-up moves the picked wagon with the moving part, the standing part not at all')
  end subroutine take_up

  !> Clusters that are not paths go to the dense solve: a body in three rows, rows that order
  !> the path both ways (a buffer and a coupler on one body), two walls.
  subroutine not_paths()
    work%row_body(:, 1:3) = reshape([1, 2, 1, 3, 1, 4], [2, 3])
    work%row_normal(:, 1:3) = reshape([-1.0_wp, 1.0_wp, -1.0_wp, 1.0_wp, -1.0_wp, 1.0_wp], [2, 3])
    call check(.not. path_order(work%path, 4, work%row_body(:, 1:3), work%row_normal(:, 1:3)), 'a star is not a path')
    work%row_body(:, 1:2) = reshape([1, 2, 2, 3], [2, 2])
    work%row_normal(:, 1:2) = reshape([-1.0_wp, 1.0_wp, 1.0_wp, -1.0_wp], [2, 2])
    call check(.not. path_order(work%path, 3, work%row_body(:, 1:2), work%row_normal(:, 1:2)), &
      'a path ordered both ways is not taken')
    work%row_normal(:, 1:2) = reshape([-1.0_wp, 1.0_wp, -1.0_wp, 1.0_wp], [2, 2])
    call check(path_order(work%path, 3, work%row_body(:, 1:2), work%row_normal(:, 1:2)), 'a path ordered one way is')
    work%row_body(:, 1:3) = reshape([0, 1, 1, 2, 0, 2], [2, 3])
    work%row_normal(:, 1:3) = reshape([0.0_wp, 1.0_wp, -1.0_wp, 1.0_wp, 0.0_wp, -1.0_wp], [2, 3])
    call check(.not. path_order(work%path, 2, work%row_body(:, 1:3), work%row_normal(:, 1:3)), &
      'a path between two walls is not taken')
  end subroutine not_paths

  subroutine show(n, nr, stuck, sgn, active)
    integer, intent(in) :: n, nr
    logical, intent(in) :: stuck(:), active(:)
    real(wp), intent(in) :: sgn(:)
    integer :: i
    print '(a, i0, a, i0)', 'differs: n = ', n, ' rows = ', nr
    do i = 1, n
      print '(a, i3, 6es25.17, a, l2, f5.1, a, l2, f5.1)', ' body', i, work%mass(i), work%force(i), work%rate(i), &
        work%friction(i), work%static(i), work%velocity(i), '  dense', stuck(i), sgn(i), '  path', work%stuck(i), &
        work%sgn(i)
    end do
    do i = 1, nr
      print '(a, i3, 2i4, 2f5.1, a, l2, a, l2)', ' row', i, work%row_body(:, i), work%row_normal(:, i), '  dense', &
        active(i), '  path', work%active(i)
    end do
  end subroutine show

  real(wp) function rand()
    call random_number(rand)
  end function rand

  real(wp) function pick(values)
    real(wp), intent(in) :: values(:)
    pick = values(1 + min(size(values) - 1, int(rand() * size(values))))
  end function pick

  !> A random permutation of 1..n in p(1:n).
  subroutine shuffle(p, n)
    integer, intent(out) :: p(:)
    integer, intent(in) :: n
    integer :: i, j, tmp
    p(1:n) = [(i, i = 1, n)]
    do i = n, 2, -1
      j = 1 + int(rand() * i)
      tmp = p(i)
      p(i) = p(j)
      p(j) = tmp
    end do
  end subroutine shuffle
end program test_path_mode

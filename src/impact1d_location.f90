!> Event location within a step (METHOD.md 4): the earliest gap closing, sliding body
!> stopping or mode condition failing on the step's dense output, its refinement on the
!> integrator's own state, and the quiet times before which nothing needs locating.
module impact1d_location
  use impact1d_kinds, only: wp, eps_wp
  use impact1d_scene, only: scene_type
  use impact1d_modes, only: mode_type, max_holds, pair_rows
  use impact1d_events, only: earliest_crossing, stop_force_cubic
  use impact1d_impacts, only: normal_velocity
  use impact1d_state, only: lane_state_type
  use impact1d_lanes, only: max_lanes
  use impact1d_yardsticks, only: velocity_rounding, force_scale
  use impact1d_contacts, only: gap, gap_tolerance, gap_tolerance_along, displacement, stop_gap_band, stop_force_band
  use impact1d_stepping, only: rk4_type, dense_output
  use impact1d_loads, only: applied_force, applied_rate, state_force, add_stop_force
  implicit none
  private
  public :: watch_type, hold_crossing, refine, constraints_hold, first_negative
  public :: located_type, located_none, located_row, located_body, located_hold, located_stop

  !> What a location found: a row's gap closing (a compliant stop's too: its engagement), a
  !> sliding body stopping, a mode condition failing (located_hold, no index), a compliant
  !> stop's force k p + c p' crossing zero (located_stop: its release, or its engagement
  !> again while still inside), or nothing.
  integer, parameter :: located_none = 0, located_row = 1, located_body = 2, located_hold = 3, located_stop = 4
  type :: located_type
    integer :: kind = located_none
    integer :: index = 0      !< the row or the body
  end type located_type

  !> What the current mode needs watched.
  type :: watch_type
    !> Until when each open gap (row) and each sliding body (N, allocated in run) needs no
    !> location.
    real(wp) :: quiet_row(pair_rows) = -huge(1.0_wp)
    real(wp), allocatable :: quiet_body(:)
    !> Something in the mode can end it (else its steps need no location at all).
    logical :: watching = .true.
  contains
    procedure :: locate
    procedure :: find_quiet_times
    procedure :: forget_quiet_times
    procedure :: quiet_time
  end type watch_type

contains

  !> Nothing is known quiet (until find_quiet_times).
  pure subroutine forget_quiet_times(self)
    class(watch_type), intent(inout) :: self
    self%quiet_row = -huge(1.0_wp)
    self%quiet_body(:) = -huge(1.0_wp)
  end subroutine forget_quiet_times

  !> The first of the quiet times: steps ending before it need no location.
  pure real(wp) function quiet_time(self)
    class(watch_type), intent(in) :: self
    quiet_time = min(minval(self%quiet_row), minval(self%quiet_body))
  end function quiet_time

  !> Earliest event in (0, step]: a gap closing, a sliding body stopping, a mode condition
  !> failing: which says what (nothing if theta is past the step).
  subroutine locate(self, scene, mode, constant_forcing, polynomial_forcing, a, b, step, theta, which)
    class(watch_type), intent(in) :: self
    type(scene_type), intent(in) :: scene
    type(mode_type), intent(in) :: mode
    logical, intent(in) :: constant_forcing
    !> The dense output is exact (the motion is a cubic): else its own error counts too.
    logical, intent(in) :: polynomial_forcing
    type(lane_state_type), intent(in) :: a, b
    real(wp), intent(in) :: step
    real(wp), intent(out) :: theta
    type(located_type), intent(out) :: which
    real(wp) :: p(0:3), q(0:3), candidate, scale, c(3, max_lanes), f(max_lanes), df(max_lanes)
    real(wp) :: acc_rounding(max_lanes), acc0(max_lanes)
    integer :: k, i
    logical :: have_dense, have_acc_rounding, have_acc0

    theta = huge(1.0_wp)
    have_dense = .false.
    have_acc_rounding = .false.
    have_acc0 = .false.
    do k = 1, scene%n_rows
      if (mode%active(k)) cycle
      if (a%t + step < self%quiet_row(k)) cycle
      if (.not. have_dense) call dense_output(a, b, step, c)
      have_dense = .true.
      p(0) = gap(scene, k, a)
      p(1:3) = scene%pair%normal(1, k) * c(:, 1) + scene%pair%normal(2, k) * c(:, 2)
      ! The common case first: the gap cannot reach zero within the step.
      if (p(0) - step * (abs(p(1)) + step * (abs(p(2)) + step * abs(p(3)))) > 0.0_wp) cycle
      ! Only a gap that may close needs the forces' rounding (a sine costs two evaluations).
      if (.not. have_acc_rounding) then
        call state_force(scene, a, f, mode%engaged)
        call applied_rate(scene, a%t, a%v, df)
        acc_rounding = 1.0e3_wp * eps_wp * force_scale(scene, f, df) / scene%pair%mass
        if (.not. polynomial_forcing) then
          call mode%acceleration(f, acc0)
          have_acc0 = .true.
        end if
      end if
      have_acc_rounding = .true.
      q = gap_tolerance_along(scene, k, a, c, acc_rounding)
      ! A motion that is not a cubic (a sine, springs, dampers) is only approximated by the
      ! step's Hermite cubic: its curvature at the start differs from the true one, the gap
      ! acceleration, by up to the interpolation error. A gap released at this instant with
      ! a tiny acceleration away would dip below zero on the cubic alone (a spring-mass
      ! leaving a wall as the sine force turns: located again and again at theta = 0).
      ! The dips the cubic cannot resolve do not count; a real crossing still does, and
      ! the step's end is checked on the integrator's own state (constraints_hold).
      if (.not. polynomial_forcing) q(2) = q(2) + abs(p(2) - 0.5_wp * dot_product(scene%pair%normal(:, k), acc0))
      candidate = earliest_crossing(p, step, q)
      if (candidate < theta) then
        theta = candidate
        which = located_type(located_row, k)
      end if
    end do
    do i = 1, scene%n_bodies
      if (scene%body_static(i) == 0.0_wp .or. mode%sgn(i) == 0.0_wp) cycle
      if (a%t + step < self%quiet_body(i)) cycle
      if (.not. have_dense) call dense_output(a, b, step, c)
      have_dense = .true.
      ! Sliding velocity in its own direction: the derivative of the Hermite cubic.
      p = mode%sgn(i) * [c(1, i), 2.0_wp * c(2, i), 3.0_wp * c(3, i), 0.0_wp]
      scale = max(abs(a%v(i)), abs(b%v(i)), abs(b%v(i) - a%v(i)))
      q = [velocity_rounding * scale, 0.0_wp, 0.0_wp, 0.0_wp]
      ! As for the gaps above: under a motion that is not a cubic, the cubic's slope at the
      ! start is not the true acceleration. A body breaking away where static and sliding
      ! friction are equal starts with zero acceleration; the cubic's slope there (from the
      ! step's ends) would dip its velocity below zero at once, a stop located at theta = 0
      ! again and again. The dip the cubic cannot resolve does not count.
      if (.not. polynomial_forcing) then
        if (.not. have_acc0) then
          call state_force(scene, a, f, mode%engaged)
          call mode%acceleration(f, acc0)
        end if
        have_acc0 = .true.
        q(1) = q(1) + abs(p(1) - mode%sgn(i) * acc0(i))
      end if
      candidate = earliest_crossing(p, step, q)
      if (candidate < theta) then
        theta = candidate
        which = located_type(located_body, i)
      end if
    end do
    if (scene%n_stops > 0) then
      if (.not. have_dense) call dense_output(a, b, step, c)
      have_dense = .true.
      call locate_stops(scene, mode, a, c, step, theta, which)
    end if
    ! Under constant forces the mode's conditions are constant: they held when it began.
    if (mode%n_hold > 0 .and. .not. constant_forcing) then
      if (scene%springs%present .and. .not. have_dense) call dense_output(a, b, step, c)
      candidate = hold_crossing(scene, mode, a, c, step)
      if (candidate < theta) then
        theta = candidate
        which = located_type(located_hold, 0)
      end if
    end if
  end subroutine locate

  !> The compliant stops' events on the step's dense output c from a (docs/method.md section
  !> 10), if earlier than theta: an open stop's gap closing (its engagement: located_row),
  !> an engaged stop's force F = -(k gap + c gap') falling through zero (its release:
  !> located_stop), and a stop released inside (gap < 0) whose F rises through zero (engaged
  !> again: located_stop). On the cubic gap(theta) F is a cubic too; its tolerance is the
  !> gap's (gap_tolerance_along, with the cubic's own error when the motion is not one)
  !> carried through the same combination.
  subroutine locate_stops(scene, mode, a, c, step, theta, which)
    type(scene_type), intent(in) :: scene
    type(mode_type), intent(in) :: mode
    type(lane_state_type), intent(in) :: a
    real(wp), intent(in) :: c(3, max_lanes), step
    real(wp), intent(inout) :: theta
    type(located_type), intent(inout) :: which
    real(wp) :: g(0:3), q(0:3), force(0:3), tol(0:3), f(max_lanes), df(max_lanes), acc0(max_lanes)
    real(wp) :: acc_rounding(max_lanes)
    integer :: r
    logical :: engaged
    call state_force(scene, a, f, mode%engaged)
    call applied_rate(scene, a%t, a%v, df)
    acc_rounding = 1.0e3_wp * eps_wp * force_scale(scene, f, df) / scene%pair%mass
    call mode%acceleration(f, acc0)
    do r = scene%n_rows + 1, scene%n_rows + scene%n_stops
      engaged = btest(mode%engaged, r - scene%n_rows - 1)
      g(0) = gap(scene, r, a)
      g(1:3) = scene%pair%normal(1, r) * c(:, 1) + scene%pair%normal(2, r) * c(:, 2)
      q = gap_tolerance_along(scene, r, a, c, acc_rounding)
      q(2) = q(2) + abs(g(2) - 0.5_wp * dot_product(scene%pair%normal(:, r), acc0))
      ! Released at the limit (c = 0: at gap = 0), within its rounding, the stop is open.
      if (.not. engaged .and. g(0) >= -stop_gap_band(scene, r, a)) then
        call take_earlier(earliest_crossing(g, step, [max(q(0), stop_gap_band(scene, r, a)), q(1:3)]), &
          located_type(located_row, r), theta, which)
        cycle
      end if
      call stop_force_cubic(scene%row_k(r), scene%row_c(r), g, q, force, tol)
      tol(0) = max(tol(0), stop_force_band(scene, r, a))
      ! Engaged: F >= 0 until it falls through zero. Released inside: F < 0 until it rises.
      if (.not. engaged) force = -force
      call take_earlier(earliest_crossing(force, step, tol), located_type(located_stop, r), theta, which)
    end do
  end subroutine locate_stops

  !> theta, which := candidate, found when the candidate is earlier.
  pure subroutine take_earlier(candidate, found, theta, which)
    real(wp), intent(in) :: candidate
    type(located_type), intent(in) :: found
    real(wp), intent(inout) :: theta
    type(located_type), intent(inout) :: which
    if (candidate < theta) then
      theta = candidate
      which = found
    end if
  end subroutine take_earlier

  !> Earliest time in [0, step] at which a condition of the mode (a contact force, a static
  !> friction margin) has turned negative, for the step from state a with dense output c.
  !> Without springs they depend on time only: linear within a step under piecewise-linear
  !> forcing, so the ends decide; a sine is sampled finer before bisection. With springs they
  !> follow the state, read on the dense output, sampled as finely as the springs' frequency asks.
  real(wp) function hold_crossing(scene, mode, a, c, step) result(theta)
    type(scene_type), intent(in) :: scene
    type(mode_type), intent(in) :: mode
    type(lane_state_type), intent(in) :: a
    real(wp), intent(in) :: c(3, max_lanes), step
    real(wp) :: lo, hi, mid, tol, t0
    integer :: n_sub, j
    real(wp), parameter :: two_pi = 2.0_wp * acos(-1.0_wp)
    theta = huge(1.0_wp)
    t0 = a%t
    tol = hold_tolerance(scene, mode, a)
    n_sub = 1
    ! (the fastest sine's count is the largest of the sines' counts: rounding is monotone)
    if (scene%forcing%fastest > 0.0_wp) n_sub = max(n_sub, ceiling(16.0_wp * step * scene%forcing%fastest / two_pi))
    if (scene%springs%present) n_sub = max(n_sub, &
      ceiling(16.0_wp * step * scene%springs%omega / two_pi))
    lo = 0.0_wp
    do j = 1, n_sub
      hi = step * real(j, wp) / real(n_sub, wp)
      if (worst_hold(scene, mode, a, c, hi) < -tol) then
        ! Bisection to the first instant at which a condition has failed (within rounding):
        ! there the new mode's accelerations have the sign of the change. At the last
        ! instant that held, a released contact would be left a rounding-level acceleration
        ! back into it and close again at once, for ever.
        do while (hi - lo > 2.0_wp * eps_wp * max(abs(t0 + hi), step))
          mid = 0.5_wp * (lo + hi)
          if (worst_hold(scene, mode, a, c, mid) < 0.0_wp) then
            hi = mid
          else
            lo = mid
          end if
        end do
        theta = hi
        return
      end if
      lo = hi
    end do
  end function hold_crossing

  !> The mode's weakest condition theta into the step from a (dense output c).
  real(wp) function worst_hold(scene, mode, a, c, theta)
    type(scene_type), intent(in) :: scene
    type(mode_type), intent(in) :: mode
    type(lane_state_type), intent(in) :: a
    real(wp), intent(in) :: c(3, max_lanes), theta
    real(wp) :: values(max_holds), f(max_lanes), dx(max_lanes), v(max_lanes)
    if (scene%springs%present) then
      dx = a%x_lo + theta * (c(1, :) + theta * (c(2, :) + theta * c(3, :)))
      v = c(1, :) + theta * (2.0_wp * c(2, :) + 3.0_wp * theta * c(3, :))
      call applied_force(scene, a%t + theta, a%x, dx, v, f)
      if (mode%engaged /= 0) call add_stop_force(scene, mode%engaged, a%x, dx, v, f)
    else
      call scene%forcing%force(a%t + theta, f)
    end if
    values = mode%holds(f)
    worst_hold = minval(values(1:mode%n_hold))
  end function worst_hold

  real(wp) function hold_tolerance(scene, mode, a)
    type(scene_type), intent(in) :: scene
    type(mode_type), intent(in) :: mode
    type(lane_state_type), intent(in) :: a
    real(wp) :: f(max_lanes), df(max_lanes)
    call state_force(scene, a, f, mode%engaged)
    call applied_rate(scene, a%t, a%v, df)
    hold_tolerance = 1.0e3_wp * eps_wp * force_scale(scene, f, df) + tiny(1.0_wp)
  end function hold_tolerance

  !> Re-take the step to the located time and polish it by Newton's method on the watched
  !> function evaluated on the integrator's own state: under polynomial forcing the dense
  !> output is exact and the first check passes; under a sine it is approximate. A sliding
  !> body's stop under such forcing was located on the cubic's velocity, whose root may come
  !> before the exact one: Newton may then go on up to the step taken (taken).
  subroutine refine(rk, scene, mode, a, step, which, b, taken)
    type(rk4_type), intent(inout) :: rk
    type(scene_type), intent(in) :: scene
    type(mode_type), intent(in) :: mode
    type(lane_state_type), intent(in) :: a
    real(wp), intent(inout) :: step
    type(located_type), intent(in) :: which
    type(lane_state_type), intent(inout) :: b
    real(wp), intent(in) :: taken
    real(wp) :: value, slope, tol, located_step, f(max_lanes), acc(max_lanes)
    integer :: iteration
    located_step = step
    if (which%kind == located_body .and. .not. rk%polynomial_forcing) located_step = taken
    call rk%step(scene, mode, a, step, b)
    if (which%kind /= located_row .and. which%kind /= located_body .and. which%kind /= located_stop) return
    do iteration = 1, 8
      associate (i => which%index, k => which%index)
        if (which%kind == located_stop) then
          ! A stop's force F = -(k gap + c gap'), its rate -(k gap' + c gap'').
          call state_force(scene, b, f, mode%engaged)
          call mode%acceleration(f, acc)
          slope = normal_velocity(scene, k, b%v)
          value = -(scene%row_k(k) * gap(scene, k, b) + scene%row_c(k) * slope)
          tol = stop_force_band(scene, k, b)
          slope = -(scene%row_k(k) * slope + scene%row_c(k) * dot_product(scene%pair%normal(:, k), acc))
        else if (which%kind == located_body) then
          value = b%v(i)
          call state_force(scene, b, f, mode%engaged)
          call mode%acceleration(f, acc)
          slope = acc(i)
          tol = velocity_rounding * max(abs(a%v(i)), abs(value))
        else
          value = gap(scene, k, b)
          slope = normal_velocity(scene, k, b%v)
          tol = gap_tolerance(scene, k, b, displacement(scene, k, a, b))
        end if
      end associate
      if (abs(value) <= tol .or. slope == 0.0_wp) exit
      ! Newton stays inside the step that was located, or the clock could pass a stop.
      if (step - value / slope <= 0.0_wp .or. step - value / slope > located_step) exit
      step = step - value / slope
      call rk%step(scene, mode, a, step, b)
    end do
  end subroutine refine

  !> No step from s may end (at b) with a gap below zero beyond rounding, nor a sliding body
  !> past zero. The row whose closing ended the step (located, else 0) is put on its
  !> constraint at the event point, so its own rounding does not count.
  pure logical function constraints_hold(scene, mode, s, b, located)
    type(scene_type), intent(in) :: scene
    type(mode_type), intent(in) :: mode
    type(lane_state_type), intent(in) :: s, b
    integer, intent(in) :: located
    integer :: k, i
    constraints_hold = .true.
    do k = 1, scene%n_rows
      if (mode%active(k) .or. k == located) cycle
      if (gap(scene, k, b) < -gap_tolerance(scene, k, b, displacement(scene, k, s, b))) constraints_hold = .false.
    end do
    do i = 1, scene%n_bodies
      if (scene%body_static(i) == 0.0_wp .or. mode%sgn(i) == 0.0_wp) cycle
      if (mode%sgn(i) * b%v(i) < -velocity_rounding * max(abs(s%v(i)), abs(b%v(i)), &
          abs(b%v(i) - s%v(i)))) constraints_hold = .false.
    end do
  end function constraints_hold

  !> Under constant forces a mode's motion is an exact quadratic, so the first instant an
  !> open gap can close, or a sliding body can stop, is known in closed form; steps that end
  !> well before it (1% of the way, far beyond rounding) need no location for it. Only a
  !> shortcut: the location itself still finds the event.
  pure subroutine find_quiet_times(self, scene, mode, s, constant_acceleration)
    class(watch_type), intent(inout) :: self
    type(scene_type), intent(in) :: scene
    type(mode_type), intent(in) :: mode
    type(lane_state_type), intent(in) :: s
    real(wp), intent(in) :: constant_acceleration(max_lanes)
    integer :: k, i
    ! What is not watched needs no location.
    self%quiet_row = huge(1.0_wp)
    self%quiet_body(:) = huge(1.0_wp)
    do k = 1, scene%n_rows
      if (mode%active(k)) cycle
      self%quiet_row(k) = s%t + 0.99_wp * first_negative(gap(scene, k, s), normal_velocity(scene, k, s%v), &
        dot_product(scene%pair%normal(:, k), constant_acceleration))
    end do
    do i = 1, scene%n_bodies
      if (scene%body_static(i) == 0.0_wp .or. mode%sgn(i) == 0.0_wp) cycle
      self%quiet_body(i) = s%t + 0.99_wp * first_negative(mode%sgn(i) * s%v(i), &
        mode%sgn(i) * constant_acceleration(i), 0.0_wp)
    end do
  end subroutine find_quiet_times

  !> First tau > 0 with g0 + u tau + a tau^2 / 2 < 0, for g0 >= 0 (0 if g0 < 0, huge if never).
  pure real(wp) function first_negative(g0, u, a) result(tau)
    real(wp), intent(in) :: g0, u, a
    real(wp) :: disc, q
    tau = huge(1.0_wp)
    if (g0 < 0.0_wp) then
      tau = 0.0_wp
    else if (a == 0.0_wp) then
      if (u < 0.0_wp) tau = g0 / (-u)
    else
      disc = u**2 - 2.0_wp * a * g0
      if (disc < 0.0_wp) return
      ! Roots of a/2 tau^2 + u tau + g0 by the stable pair q/(a/2) and g0/q.
      q = -0.5_wp * (u + sign(sqrt(disc), u))
      if (a > 0.0_wp) then
        if (u < 0.0_wp .and. q /= 0.0_wp) tau = g0 / q        ! the smaller positive root
      else
        tau = max(q / (0.5_wp * a), merge(g0 / q, 0.0_wp, q /= 0.0_wp))   ! the positive root
      end if
      tau = max(tau, 0.0_wp)
    end if
    if (tau /= tau) tau = 0.0_wp
  end function first_negative
end module impact1d_location

!> Everything that happens at one instant (METHOD.md 5-6): closed contacts snapped,
!> impacts resolved (one joint inelastic impact, then sequential impulses), bounce series
!> whose rest is below the clock's resolution put to rest (Zeno), stopped bodies zeroed,
!> the new mode from the complementarity problem, and the log of what changed.
!> On the state in lanes (impact1d_lanes) and the pair's masses, friction bounds and normals
!> (scene%pair, the mode kernel's view): one body is the pair with an idle second lane.
module impact1d_event_point
  use impact1d_kinds, only: wp, eps_wp
  use impact1d_error, only: error_type, raise, status_simulation, fmt
  use impact1d_lanes, only: max_lanes
  use impact1d_scene, only: scene_type
  use impact1d_modes, only: mode_type, solve_mode, pair_rows
  use impact1d_impacts, only: normal_velocity, impulse, most_approaching, restitution_of, &
    kinetic_energy, joint_inelastic, inelastic_projection
  use impact1d_output, only: sink_type, run_stats, class_impact, class_rest, class_release, class_stick, class_slip
  use impact1d_state, only: lane_state_type, add_compensated
  use impact1d_yardsticks, only: gap_rounding, velocity_rounding, time_rounding, energy_rounding, force_scale, &
    same_instant
  use impact1d_contacts, only: gap, gap_tolerance, snap, rigid_pair, u_tolerance, u_tolerances, stop_gap_band, &
    stop_force_band
  use impact1d_stepping, only: rk4_type
  use impact1d_location, only: watch_type, located_type, located_row, located_body, located_stop
  use impact1d_loads, only: state_force, applied_rate
  use impact1d_event_log, only: event_log_type, log_event
  use impact1d_accumulation, only: join_cycle
  implicit none
  private
  public :: event_point, bounce_series_time


contains

  !> The event point at s%t. which: what the location found (a row, a body, a mode
  !> condition) or nothing; initial: the start of the run (no mode yet). Leaves the new mode,
  !> what it needs watched and the integrator's constant acceleration set. s: the run's state,
  !> in lanes (the run keeps it there: impact1d_solver's run).
  subroutine event_point(scene, initial, which, s, mode, event_log, watch, rk, sink, stats, error)
    type(scene_type), intent(in) :: scene
    logical, intent(in) :: initial
    type(located_type), intent(in) :: which
    type(lane_state_type), intent(inout) :: s
    type(mode_type), intent(inout) :: mode
    type(event_log_type), intent(inout) :: event_log
    type(watch_type), intent(inout) :: watch
    type(rk4_type), intent(inout) :: rk
    class(sink_type), intent(inout) :: sink
    type(run_stats), intent(inout) :: stats
    type(error_type), allocatable, intent(inout) :: error
    logical :: closed(pair_rows), candidate(pair_rows), resting(max_lanes), found
    logical :: pushed(pair_rows), hit(pair_rows)
    real(wp), dimension(max_lanes) :: f, df, v_before, v_after, moving_sign, acc
    ! Velocity scale of each body entering this event point: impulses redistribute
    ! velocity but cannot create precision, so what is below its rounding is zero.
    real(wp) :: entry_scale(max_lanes)
    integer :: k, i, n_impulses
    type(mode_type) :: new_mode
    logical :: switched

    if (scene%n_stops > 0) then
      call state_force(scene, s, f, mode%engaged)
      call mode%acceleration(f, acc)
      if (initial) acc = f / scene%pair%mass
      call switch_stops(scene, which, s, acc, mode%engaged, sink, stats, switched)
      if (switched .or. initial) call rk%set_springs(scene, mode%engaged)
    end if
    call state_force(scene, s, f, mode%engaged)
    call applied_rate(scene, s%t, s%v, df)
    closed = .false.
    do k = 1, scene%n_rows
      closed(k) = (which%kind == located_row .and. which%index == k) .or. &
        gap(scene, k, s) <= gap_tolerance(scene, k, s, 0.0_wp)
      ! The user's numbers carry their decimal rounding (7.553 - 7.122 is not 0.431): at the
      ! start, a gap within it is contact, as the validator accepted it.
      if (initial) closed(k) = closed(k) .or. gap(scene, k, s) <= &
        gap_rounding * max(maxval(abs(scene%pair%normal(:, k) * s%x)), abs(scene%row_offset(k)))
    end do
    ! A rigid link (d_min = d_max) is one constraint seen from both sides.
    do k = 1, scene%n_rows
      if (scene%row_partner(k) > 0) closed(k) = closed(k) .or. closed(scene%row_partner(k))
    end do
    do k = 1, scene%n_rows
      if (closed(k)) call snap(scene, k, closed, s)
    end do
    ! A sliding body whose stop was located, or that stopped within rounding (its velocity
    ! change over a step is the scale), is at rest.
    call mode%acceleration(f, acc)
    if (initial) acc = f / scene%pair%mass     ! no mode yet: the free accelerations set the scale
    entry_scale = abs(s%v) + abs(acc) * scene%dt
    if (same_instant(scene, s%t, event_log%scale_time)) entry_scale = max(entry_scale, event_log%scale)
    do i = 1, 2
      if (scene%pair%static_friction(i) == 0.0_wp) cycle
      if ((which%kind == located_body .and. which%index == i) .or. &
          abs(s%v(i)) <= velocity_rounding * abs(acc(i)) * scene%dt) call zero_velocity(scene, s, i)
    end do

    ! Perfectly inelastic contacts closed together take one joint impact: sequential
    ! impulses would only approach it geometrically (a body pinned by a heavier one).
    hit = .false.
    if (joint_inelastic(scene, closed)) then
      v_before = s%v
      call inelastic_projection(scene, closed, s%v, u_tolerances(scene, mode, s, entry_scale), v_after, pushed)
      if (any(pushed)) then
        call check_dissipative(scene, s%t, v_before, v_after, error)
        if (allocated(error)) return
        call apply(scene, s, v_after)
        ! A row between the bodies pushed both: each takes the larger scale.
        do k = 1, scene%n_rows
          if (pushed(k) .and. all(scene%pair%normal(:, k) /= 0.0_wp)) entry_scale = maxval(entry_scale)
        end do
        do k = 1, scene%n_rows
          if (pushed(k)) call log_event(scene, sink, stats, s%t, class_impact, k, v_before, v_after)
        end do
        hit = pushed
      end if
    end if
    n_impulses = 0
    do
      k = most_approaching(scene, closed, s%v, u_tolerances(scene, mode, s, entry_scale))
      if (k == 0) exit
      n_impulses = n_impulses + 1
      if (n_impulses > scene%max_impulses) then
        call raise(error, status_simulation, 'at t = ' // trim(fmt(s%t)) // ': the impacts did not settle after ' &
          // trim(fmt(scene%max_impulses)) // ' impulses (typically a light body squeezed between a much ' // &
          'heavier one and a wall or stop: the impulses pass back and forth, more of them the larger ' // &
          'the mass ratio; raise &run max_impulses)')
        return
      end if
      v_before = s%v
      call impulse(scene, k, restitution_of(scene, k, closed), s%v, v_after, rigid_pair(scene, closed))
      call check_dissipative(scene, s%t, v_before, v_after, error)
      if (allocated(error)) return
      call apply(scene, s, v_after)
      if (all(scene%pair%normal(:, k) /= 0.0_wp)) entry_scale = maxval(entry_scale)
      call log_event(scene, sink, stats, s%t, class_impact, k, v_before, v_after)
      hit(k) = .true.
    end do
    if (any(hit)) call cut_cycle(scene, hit, closed, s, event_log, sink, stats)

    event_log%scale_time = s%t
    event_log%scale = entry_scale

    ! Contacts left with a rounding-level normal velocity are closed and still. Approach left
    ! at two closed contacts that no one of them can remove goes jointly (their vertex: the
    ! joint inelastic impact): removed one contact at a time it would pass back and forth, a
    ! fraction smaller each time (a body on a wall under a heavier one).
    call zero_stopped(scene, s, acc, entry_scale)
    if (.not. rigid_pair(scene, closed)) then
      call inelastic_projection(scene, closed, s%v, spread(0.0_wp, 1, pair_rows), v_after, pushed)
      if (count(pushed) >= 2) call apply(scene, s, v_after)
    end if
    do k = 1, scene%n_rows
      if (.not. closed(k)) cycle
      if (abs(normal_velocity(scene, k, s%v)) <= u_tolerance(scene, mode, s, k, entry_scale) .and. &
          normal_velocity(scene, k, s%v) /= 0.0_wp) then
        call impulse(scene, k, 0.0_wp, s%v, v_after, rigid_pair(scene, closed))
        call apply(scene, s, v_after)
      end if
    end do

    ! Zeno: a bounce series whose remaining time is below the clock's resolution ends in
    ! rest now; the rest is logged at the series' accumulation time.
    do k = 1, scene%n_rows
      if (.not. closed(k)) cycle
      call settle_bounce_series(scene, mode, k, f, df, closed, entry_scale, s, event_log, sink, stats)
    end do

    ! Impulses can leave a rounding-level velocity on a body that had stopped; it is zero.
    call zero_stopped(scene, s, acc, entry_scale)
    ! A body still against the other one (a closed slot limit) that has stopped has stopped
    ! too: its velocity is the contact's rounding-level normal velocity.
    do k = 1, scene%n_rows
      if (.not. closed(k) .or. any(scene%pair%normal(:, k) == 0.0_wp)) cycle
      if (abs(normal_velocity(scene, k, s%v)) > u_tolerance(scene, mode, s, k, entry_scale)) cycle
      do i = 1, 2
        if (s%v(i) == 0.0_wp) call zero_velocity(scene, s, 3 - i)
      end do
    end do

    ! Dampers pull with the velocities the impacts left.
    if (scene%springs%has_damper) then
      call state_force(scene, s, f, mode%engaged)
      call applied_rate(scene, s%t, s%v, df)
    end if
    call candidates(scene, mode, s, entry_scale, closed, candidate, resting, moving_sign)
    call solve_mode(scene%pair, f, df, candidate, resting, moving_sign, new_mode, found, force_scale(scene, f, df))
    if (.not. found) then
      call raise(error, status_simulation, 'at t = ' // trim(fmt(s%t)) // &
        ': no consistent contact and friction state (complementarity problem has no solution)')
      return
    end if

    call log_mode_change(scene, initial, f, df, candidate, new_mode, s, event_log, sink, stats)
    new_mode%engaged = mode%engaged
    mode = new_mode
    call watch%forget_quiet_times()
    if (rk%constant_forcing) then
      call mode%acceleration(scene%forcing%constant_lanes, rk%constant_acceleration)
      call watch%find_quiet_times(scene, mode, s, rk%constant_acceleration)
    end if
    watch%watching = mode%n_hold > 0 .or. any(.not. mode%active(:scene%n_rows)) .or. &
      any(scene%pair%static_friction > 0.0_wp .and. mode%sgn /= 0.0_wp) .or. scene%n_stops > 0
  end subroutine event_point

  !> The compliant stops at this instant (docs/method.md section 10): an open stop whose gap
  !> has closed (located, or within its rounding) engages when its ends approach, logged as
  !> an impact on its row (no velocity changes); an engaged one releases when its force
  !> F = -(k gap + c gap') has fallen to zero (located, or within rounding), logged as
  !> release_<row>; one released inside (gap < 0) engages again when F has risen to zero.
  !> acc: the accelerations in the mode so far (a stop at its limit with its ends at rest
  !> relative to each other engages when they accelerate into it).
  subroutine switch_stops(scene, which, s, acc, engaged, sink, stats, switched)
    type(scene_type), intent(in) :: scene
    type(located_type), intent(in) :: which
    type(lane_state_type), intent(in) :: s
    real(wp), intent(in) :: acc(max_lanes)
    integer, intent(inout) :: engaged   !< the stops engaged (bits)
    class(sink_type), intent(inout) :: sink
    type(run_stats), intent(inout) :: stats
    logical, intent(out) :: switched    !< a stop engaged or released
    real(wp) :: g, u, force, tol
    integer :: j, r, engaged_before
    logical :: located, engage
    engaged_before = engaged
    do j = 1, scene%n_stops
      r = scene%n_rows + j
      g = gap(scene, r, s)
      u = normal_velocity(scene, r, s%v)
      force = -(scene%row_k(r) * g + scene%row_c(r) * u)
      tol = stop_force_band(scene, r, s)
      located = (which%kind == located_row .or. which%kind == located_stop) .and. which%index == r
      ! A located crossing switches where the force is zero within rounding (refine's
      ! Newton may stop short of it: the next step finds it again); one the location missed
      ! switches where the force is past zero.
      if (btest(engaged, j - 1)) then
        if (force < -tol .or. (located .and. force <= tol)) then
          engaged = ibclr(engaged, j - 1)
          call log_event(scene, sink, stats, s%t, class_release, r, s%v, s%v)
        end if
        cycle
      end if
      if (g > stop_gap_band(scene, r, s)) cycle
      ! At the limit (gap within rounding) the stop engages when its ends approach, or, at
      ! rest relative to each other (a body set down on a compliant floor), accelerate into
      ! it (else the gap closing is located at once again and again); inside it, when its
      ! force has risen to zero.
      if (g >= -stop_gap_band(scene, r, s)) then
        engage = u < -velocity_rounding * maxval(abs(s%v)) .or. (u <= velocity_rounding * maxval(abs(s%v)) &
          .and. dot_product(scene%pair%normal(:, r), acc) < 0.0_wp)
      else
        engage = force > tol .or. (located .and. force >= -tol)
      end if
      if (engage) then
        engaged = ibset(engaged, j - 1)
        call log_event(scene, sink, stats, s%t, class_impact, r, s%v, s%v)
      end if
    end do
    switched = engaged /= engaged_before
  end subroutine switch_stops

  !> An event point whose impulses hit the rows marked, recorded; when the last points make
  !> an accumulation over several contacts (impact1d_accumulation) whose rest is near, its
  !> rows close now: snapped, the bodies they join moving as one (at rest if joined to the
  !> ground), their rests logged at the series' limit time.
  subroutine cut_cycle(scene, hit, closed, s, event_log, sink, stats)
    type(scene_type), intent(in) :: scene
    logical, intent(in) :: hit(pair_rows)
    logical, intent(inout) :: closed(pair_rows)
    type(lane_state_type), intent(inout) :: s
    type(event_log_type), intent(inout) :: event_log
    class(sink_type), intent(inout) :: sink
    type(run_stats), intent(inout) :: stats
    ! (fixed-size: gfortran puts arrays of run-time size on the heap, an allocation an event)
    real(wp) :: u(pair_rows), remaining, v(max_lanes)
    logical :: rows(pair_rows), found
    integer :: k, nr
    nr = scene%n_rows
    do k = 1, nr
      u(k) = normal_velocity(scene, k, s%v)
    end do
    call event_log%cycles%record(s%t, hit(:nr), u(:nr))
    call event_log%cycles%find_cycle(scene%row_body, scene%dt, time_rounding * max(abs(s%t), scene%dt), rows(:nr), &
      remaining, found)
    if (.not. found) return
    call event_log%cycles%forget()
    closed(:nr) = closed(:nr) .or. rows(:nr)
    do k = 1, nr
      if (rows(k)) call snap(scene, k, closed, s)
    end do
    v = s%v
    call join_cycle(scene%row_body, rows(:nr), scene%body_mass, v(:scene%n_bodies))
    call apply(scene, s, v)
    do k = 1, nr
      if (rows(k)) call event_log%begin_rest(scene, k, s%t, s%t + remaining, s%v, sink, stats)
    end do
  end subroutine cut_cycle

  !> Log what a user can see change between the old mode and new_mode: contacts that start
  !> or stop holding, bodies that come to rest or break away.
  subroutine log_mode_change(scene, initial, f, df, candidate, new_mode, s, event_log, sink, stats)
    type(scene_type), intent(in) :: scene
    logical, intent(in) :: initial, candidate(pair_rows)
    real(wp), intent(in) :: f(max_lanes), df(max_lanes)
    type(mode_type), intent(in) :: new_mode
    type(lane_state_type), intent(in) :: s
    type(event_log_type), intent(inout) :: event_log
    class(sink_type), intent(inout) :: sink
    type(run_stats), intent(inout) :: stats
    real(wp), dimension(max_lanes) :: acc, tol_a, acc_rate
    logical :: leaving, resting_now
    integer :: k, i

    call new_mode%acceleration(f, acc)
    tol_a = 1.0e3_wp * eps_wp * force_scale(scene, f, df) / scene%pair%mass
    do k = 1, scene%n_rows
      if (new_mode%active(k) .and. .not. event_log%in_contact(k)) then
        call event_log%begin_rest(scene, k, s%t, s%t, s%v, sink, stats)
      else if (event_log%in_contact(k) .and. .not. new_mode%active(k)) then
        if (.not. candidate(k) .or. &
            dot_product(scene%pair%normal(:, k), acc) > dot_product(abs(scene%pair%normal(:, k)), tol_a) .or. &
            (dot_product(scene%pair%normal(:, k), acc) >= -dot_product(abs(scene%pair%normal(:, k)), tol_a) &
            .and. dot_product(scene%pair%normal(:, k), matmul(new_mode%gain, df)) > &
            1.0e3_wp * eps_wp * sum(abs(df)) / minval(scene%body_mass))) then
          if (event_log%pending_rest(k) < huge(1.0_wp)) then
            call log_event(scene, sink, stats, s%t, class_rest, k, s%v, s%v)
            event_log%pending_rest(k) = huge(1.0_wp)
          end if
          ! Logged once time has moved on: a contact that closes again at this same
          ! instant never opened (rounding-level relabelling), and neither entry is kept.
          event_log%in_contact(k) = .false.
          event_log%release_time(k) = s%t
          event_log%release_v(:, k) = s%v
        end if
      end if
    end do
    ! A body at rest leaves it when its acceleration, or at a break-away instant (force
    ! exactly at the bound) the acceleration's rate, points along its sliding direction.
    acc_rate = matmul(new_mode%gain, df)
    do i = 1, scene%n_bodies
      if (scene%pair%static_friction(i) == 0.0_wp) cycle
      leaving = new_mode%sgn(i) * acc(i) > tol_a(i) .or. (new_mode%sgn(i) * acc(i) >= -tol_a(i) .and. &
        new_mode%sgn(i) * acc_rate(i) > 1.0e3_wp * eps_wp * sum(abs(df)) / scene%pair%mass(i))
      resting_now = s%v(i) == 0.0_wp .and. .not. leaving
      ! A body that impulses moved off its rest and that stops again at that same instant
      ! (a chain of impacts ending there) never left rest: no stick (its leaving was not
      ! logged either).
      if (resting_now .and. .not. event_log%at_rest(i) .and. .not. initial .and. &
          .not. same_instant(scene, s%t, event_log%rest_lost_time(i))) &
        call log_event(scene, sink, stats, s%t, class_stick, i, s%v, s%v)
      if (.not. resting_now .and. event_log%at_rest(i)) then
        if (s%v(i) == 0.0_wp) then
          call log_event(scene, sink, stats, s%t, class_slip, i, s%v, s%v)
        else
          event_log%rest_lost_time(i) = s%t
        end if
      end if
      event_log%at_rest(i) = resting_now
    end do
  end subroutine log_mode_change

  !> The bounce series on closed contact k, if its bodies separate slowly: gap acceleration
  !> while rising (a_up) and falling back (a_down) come from the mode with k left free, for
  !> the velocities now and with the normal velocity reversed (friction may change sides).
  !> If what remains of the series is below the clock's resolution, the contact rests now,
  !> logged at the series' accumulation time.
  subroutine settle_bounce_series(scene, mode, k, f, df, closed, entry_scale, s, event_log, sink, stats)
    type(scene_type), intent(in) :: scene
    type(mode_type), intent(in) :: mode
    integer, intent(in) :: k
    real(wp), dimension(max_lanes), intent(in) :: f, df, entry_scale
    logical, intent(in) :: closed(pair_rows)
    type(lane_state_type), intent(inout) :: s
    type(event_log_type), intent(inout) :: event_log
    class(sink_type), intent(inout) :: sink
    type(run_stats), intent(inout) :: stats
    real(wp) :: u, a_up, a_down, remaining, v_bounce(max_lanes)
    u = normal_velocity(scene, k, s%v)
    if (u <= u_tolerance(scene, mode, s, k, entry_scale)) return
    a_up = free_gap_acceleration(scene, mode, k, s, s%v, f, df, closed, entry_scale)
    if (a_up >= 0.0_wp) return
    call impulse(scene, k, 1.0_wp, s%v, v_bounce, rigid_pair(scene, closed))
    a_down = free_gap_acceleration(scene, mode, k, s, v_bounce, f, df, closed, entry_scale)
    remaining = bounce_series_time(u, a_up, a_down, restitution_of(scene, k, closed))
    ! Gaps are exact to their own size, so the series is followed until what remains of it
    ! is below the clock's resolution.
    if (remaining > time_rounding * max(abs(s%t), scene%dt)) return
    call impulse(scene, k, 0.0_wp, s%v, v_bounce, rigid_pair(scene, closed))
    call apply(scene, s, v_bounce)
    if (remaining < huge(1.0_wp)) then
      call event_log%begin_rest(scene, k, s%t, s%t + remaining, s%v, sink, stats)
    else
      call event_log%begin_rest(scene, k, s%t, s%t, s%v, sink, stats)
    end if
  end subroutine settle_bounce_series

  !> Total time of a bounce series starting at separating normal speed u > 0, rising
  !> with gap acceleration a_up < 0 and falling back with a_down, restitution r (huge if it
  !> does not end). Under constant forces each arc takes u/|a_up| + u/sqrt(a_up a_down) and
  !> the next impact speed is r u sqrt(a_down/a_up): the series is geometric, its sum
  !> closed form.
  pure real(wp) function bounce_series_time(u, a_up, a_down, r) result(remaining)
    real(wp), intent(in) :: u, a_up, a_down, r
    real(wp) :: ratio, first_arc
    remaining = huge(1.0_wp)
    if (a_down < 0.0_wp) then
      first_arc = u / (-a_up) + u / sqrt(a_up * a_down)
      ratio = r * sqrt(a_down / a_up)
      if (ratio < 1.0_wp) remaining = first_arc / (1.0_wp - ratio)
    end if
  end function bounce_series_time

  !> Normal acceleration of contact k with k left free and the others as they are, for
  !> state s with velocities v.
  real(wp) function free_gap_acceleration(scene, mode, k, s, v, f, df, closed, entry_scale) result(a_gap)
    type(scene_type), intent(in) :: scene
    type(mode_type), intent(in) :: mode
    integer, intent(in) :: k
    type(lane_state_type), intent(in) :: s
    real(wp), dimension(max_lanes), intent(in) :: v, f, df, entry_scale
    logical, intent(in) :: closed(pair_rows)
    type(mode_type) :: free_mode
    type(lane_state_type) :: probe
    logical :: candidate(pair_rows), resting(max_lanes), found
    real(wp) :: moving_sign(max_lanes), acc(max_lanes)
    probe = s
    probe%v = v
    call candidates(scene, mode, probe, entry_scale, closed, candidate, resting, moving_sign)
    candidate(k) = .false.
    call solve_mode(scene%pair, f, df, candidate, resting, moving_sign, free_mode, found, force_scale(scene, f, df))
    a_gap = 0.0_wp
    if (.not. found) return
    call free_mode%acceleration(f, acc)
    a_gap = dot_product(scene%pair%normal(:, k), acc)
  end function free_gap_acceleration

  !> Bodies whose velocity is below the rounding of what a step changes it by, or of the
  !> velocities this event point started from, are at rest.
  pure subroutine zero_stopped(scene, s, acc, entry_scale)
    type(scene_type), intent(in) :: scene
    type(lane_state_type), intent(inout) :: s
    real(wp), intent(in) :: acc(max_lanes), entry_scale(max_lanes)
    integer :: i
    do i = 1, 2
      if (s%v(i) /= 0.0_wp .and. abs(s%v(i)) <= velocity_rounding * max(abs(acc(i)) * scene%dt, &
          entry_scale(i))) call zero_velocity(scene, s, i)
    end do
  end subroutine zero_stopped

  !> Body i is at rest; the rounding-level energy it had goes to the ledger: to friction
  !> where friction stopped it (a run with no impact reports no impact loss), else to impacts.
  pure subroutine zero_velocity(scene, s, i)
    type(scene_type), intent(in) :: scene
    type(lane_state_type), intent(inout) :: s
    integer, intent(in) :: i
    if (scene%pair%static_friction(i) > 0.0_wp) then
      call add_compensated(s%friction_loss, s%friction_lo, 0.5_wp * scene%pair%mass(i) * s%v(i)**2)
    else
      s%impact_loss = s%impact_loss + 0.5_wp * scene%pair%mass(i) * s%v(i)**2
    end if
    s%v(i) = 0.0_wp
    s%v_lo(i) = 0.0_wp
  end subroutine zero_velocity

  !> An impact with restitutions <= 1 cannot raise the kinetic energy: if one ever does (to
  !> more than the rounding of its sum), the engine is wrong, and the run says so rather than
  !> return numbers booked as a negative impact loss.
  subroutine check_dissipative(scene, t, v_before, v_after, error)
    type(scene_type), intent(in) :: scene
    real(wp), intent(in) :: t, v_before(max_lanes), v_after(max_lanes)
    type(error_type), allocatable, intent(inout) :: error
    real(wp) :: ke_before, ke_after
    ke_before = kinetic_energy(scene, v_before)
    ke_after = kinetic_energy(scene, v_after)
    if (ke_after <= ke_before * (1.0_wp + energy_rounding)) return
    call raise(error, status_simulation, 'at t = ' // trim(fmt(t)) // ': internal error: an impact ' // &
      'raised the kinetic energy from ' // trim(fmt(ke_before)) // ' to ' // trim(fmt(ke_after)) // &
      ' J (velocities ' // trim(fmt(v_before(1))) // ', ' // trim(fmt(v_before(2))) // ' -> ' // &
      trim(fmt(v_after(1))) // ', ' // trim(fmt(v_after(2))) // '); please report the scene')
  end subroutine check_dissipative

  !> Set new velocities at an instant, booking the kinetic energy they remove as impact loss.
  pure subroutine apply(scene, s, v_new)
    type(scene_type), intent(in) :: scene
    type(lane_state_type), intent(inout) :: s
    real(wp), intent(in) :: v_new(max_lanes)
    s%impact_loss = s%impact_loss + kinetic_energy(scene, s%v) - kinetic_energy(scene, v_new)
    s%v = v_new
    s%v_lo = 0.0_wp
  end subroutine apply

  !> The complementarity problem's unknowns at this instant.
  pure subroutine candidates(scene, mode, s, entry_scale, closed, candidate, resting, moving_sign)
    type(scene_type), intent(in) :: scene
    type(mode_type), intent(in) :: mode
    type(lane_state_type), intent(in) :: s
    real(wp), intent(in) :: entry_scale(max_lanes)
    logical, intent(in) :: closed(pair_rows)
    logical, intent(out) :: candidate(pair_rows), resting(max_lanes)
    real(wp), intent(out) :: moving_sign(max_lanes)
    integer :: k
    candidate = .false.
    do k = 1, scene%n_rows
      candidate(k) = closed(k)
      if (candidate(k)) candidate(k) = abs(normal_velocity(scene, k, s%v)) <= u_tolerance(scene, mode, s, k, entry_scale)
    end do
    resting = scene%pair%static_friction > 0.0_wp .and. s%v == 0.0_wp
    moving_sign = 0.0_wp
    where (scene%pair%static_friction > 0.0_wp .and. s%v /= 0.0_wp) moving_sign = sign(1.0_wp, s%v)
  end subroutine candidates

end module impact1d_event_point

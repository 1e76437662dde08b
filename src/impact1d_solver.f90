!> The hybrid-system driver (METHOD.md sections 2-6): classical RK4 at the user's step
!> within a mode, in-step location of the earliest event on the step's dense output, a
!> re-step to the event time, then impacts, Zeno rest and a new mode at the event point.
!> Nothing here allocates, formats or writes per step; output goes to a sink at sample times.
module impact1d_solver
  use, intrinsic :: iso_fortran_env, only: int64
  use impact1d_kinds, only: wp, eps_wp
  use impact1d_error, only: error_type, raise, status_simulation, fmt
  use impact1d_scene, only: scene_type, n_contacts, normal, sample_time, i_slot_min, i_slot_max
  use impact1d_modes, only: mode_type, solve_mode, max_holds
  use impact1d_events, only: earliest_crossing
  use impact1d_impacts, only: normal_velocity, impulse, most_approaching, restitution_of, &
    kinetic_energy, joint_inelastic, inelastic_projection
  use impact1d_output, only: sink_type, run_stats, emit_sample, event_impact, event_rest, &
    event_release, event_stick, event_slip
  use impact1d_vissim, only: run_vissim
  use impact1d_state, only: state_type, add_compensated, renormalise, finite_state, constant_steps
  use impact1d_yardsticks, only: velocity_rounding, time_rounding, gap_rounding, force_scale, &
    same_instant
  use impact1d_contacts, only: gap, gap_tolerance, gap_tolerance_along, displacement, snap, rigid_pair
  use impact1d_stepping, only: rk4_type, book_constant_ledger, dense_output
  implicit none
  private
  public :: run, run_stats

  integer, parameter :: max_impulses = 1000000   !< per event point; elastic chains need ~pi sqrt(M/m)
  integer, parameter :: max_stalls = 10000       !< event points in a row without time advancing
  !> Work is bounded: elastic micro-bounces can make millions of genuine events a second.
  integer, parameter :: max_event_points = 2000000
  integer, parameter :: max_halvings = 60        !< retries of a step whose end violated a constraint


contains

  !> Run a scene from t = 0 to t_end, sending every dt_out sample and every event to sink
  !> (with method 'vissim', the tutorial's fixed-step scheme instead).
  subroutine run(scene, sink, stats, error)
    type(scene_type), intent(in) :: scene
    class(sink_type), intent(inout) :: sink
    type(run_stats), intent(out) :: stats
    type(error_type), allocatable, intent(out) :: error

    type(state_type) :: s, trial
    type(mode_type) :: mode
    real(wp) :: ke0, t_stop, t_break, h, h_event, pending_rest(n_contacts), sample_t
    logical :: in_contact(n_contacts), at_rest(2), located, at_stop, watching
    logical :: polynomial_forcing, event_due, glided
    real(wp) :: t_rest
    ! Velocity scale of each body entering the current event point: impulses redistribute
    ! velocity but cannot create precision, so what is below its rounding is zero.
    real(wp) :: entry_scale(2)
    type(rk4_type) :: rk
    ! Until when each open gap (1..4) and each sliding body (5, 6) needs no location.
    real(wp) :: quiet_until(n_contacts + 2)
    ! When impulses last moved each body off its rest (see the stick log in event_point).
    real(wp) :: rest_lost_time(2)
    ! A release waiting for time to move on (see begin_rest), with its velocities.
    real(wp) :: release_time(n_contacts), release_v(2, n_contacts)
    integer :: j_sample, stalls, halvings, watched, event_points
    real(wp) :: t_last_event

    if (scene%method == 'vissim') then
      call run_vissim(scene, sink, stats, error)
      return
    end if
    rk%constant_forcing = .not. (any(scene%forcing%has_table) .or. any(scene%forcing%has_sine))
    quiet_until = -huge(1.0_wp)
    rk%end_force_t = -huge(1.0_wp)
    rest_lost_time = -huge(1.0_wp)
    release_time = huge(1.0_wp)
    release_v = 0.0_wp
    polynomial_forcing = scene%forcing%is_polynomial()
    entry_scale = 0.0_wp
    event_points = 0
    watching = .true.
    s%t = 0.0_wp
    s%x = scene%x0
    s%v = scene%v0
    ke0 = kinetic_energy(scene, s%v)
    pending_rest = huge(1.0_wp)
    in_contact = .false.
    at_rest = .false.
    stalls = 0
    t_last_event = -huge(1.0_wp)

    call event_point(initial=.true., which=0)
    if (allocated(error)) return
    j_sample = 0
    call emit()

    t_break = scene%forcing%next_breakpoint(s%t)
    do while (j_sample < scene%n_samples)
      sample_t = sample_time(scene, j_sample)
      if (t_break <= s%t) t_break = scene%forcing%next_breakpoint(s%t)
      t_rest = minval(pending_rest)
      t_stop = min(sample_t, t_break, t_rest)

      located = .false.
      glided = .false.
      if (rk%constant_forcing) then
        call glide(t_stop, glided)
        if (allocated(error)) return
      end if
      at_stop = glided
      if (.not. at_stop) then
        h = step_toward(t_stop)
        halvings = 0
        do
          located = .false.
          watched = 0
          ! An event that landed exactly on the stop leaves nothing to step.
          if (h <= 0.0_wp) then
            trial = s
            exit
          end if
          call rk%step(scene, mode, s, h, trial)
          if (.not. watching) exit      ! nothing in this mode can end it: no location needed
          call locate(s, trial, h, h_event, watched)
          located = h_event <= h
          if (located) then
            h = h_event
            if (h > 0.0_wp) then
              call refine(s, h, watched, trial)
            else
              trial = s     ! the event is at the step's start: nothing to step
              exit
            end if
          end if
          ! Under polynomial forcing the dense output is exact and nothing can be missed; only
          ! a sine's approximate dense output needs the step's end checked.
          if (polynomial_forcing) exit
          if (constraints_hold(trial, merge(watched, 0, located))) exit
          ! The location missed a root (only possible for non-polynomial forcing): retry shorter.
          halvings = halvings + 1
          if (halvings > max_halvings) then
            call raise(error, status_simulation, 'at t = ' // fmt(s%t) // &
              ': no step keeps the constraints (event location failed)')
            return
          end if
          h = 0.5_wp * h
        end do

        at_stop = .not. located .and. h == (t_stop - s%t) - s%t_lo
        s = trial
        if (at_stop) then
          s%t = t_stop
          s%t_lo = 0.0_wp
        end if
        stats%steps = stats%steps + 1
        if (iand(stats%steps, 4095_int64) == 0) call sink%progress(s%t, scene%t_end)
        call check_finite()
        if (allocated(error)) return
      end if

      ! Events, table corners (the force's slope changes) and accumulation times need an
      ! event point; a sample time does not.
      event_due = located
      if (.not. event_due .and. at_stop) event_due = t_stop == t_break .or. t_stop == t_rest
      ! A stop reached by quiet steps has no gap near closing.
      if (.not. event_due .and. at_stop .and. .not. glided) event_due = impact_due()
      if (event_due) then
        if (same_instant(scene, s%t, t_last_event)) then
          stalls = stalls + 1
          if (stalls > max_stalls) then
            call raise(error, status_simulation, 'at t = ' // fmt(s%t) // ': ' // fmt(max_stalls) // &
              ' events without time advancing (the contacts chatter)')
            return
          end if
        else
          stalls = 0
        end if
        t_last_event = s%t
        call flush_releases(.false.)
        event_points = event_points + 1
        if (event_points > max_event_points) then
          call raise(error, status_simulation, 'at t = ' // fmt(s%t) // ': more than ' // fmt(max_event_points) // &
            ' events (a bounce that never settles, such as r = 1 under a pressing force, makes them without end)')
          return
        end if
        call flush_pending_rest()
        call event_point(initial=.false., which=merge(watched, 0, located))
        if (allocated(error)) return
      end if
      if (at_stop .and. s%t == sample_t) call emit()
    end do
    call flush_releases(.true.)
    call sink%end_progress()

  contains

    subroutine emit()
      call emit_sample(sink, stats, s%t, s%x, s%v, scene%mass, ke0, s%work, s%friction_loss, s%impact_loss)
      j_sample = j_sample + 1
    end subroutine emit

    subroutine log_event(kind, v_before, v_after)
      integer, intent(in) :: kind
      real(wp), intent(in) :: v_before(2), v_after(2)
      stats%events(kind) = stats%events(kind) + 1
      call sink%put_event(s%t, kind, v_before, v_after)
    end subroutine log_event

    !> Rest after an accumulation of impacts is logged at the accumulation time.
    subroutine flush_pending_rest()
      integer :: k
      do k = 1, n_contacts
        if (pending_rest(k) <= s%t) then
          call log_event(event_rest + k, s%v, s%v)
          pending_rest(k) = huge(1.0_wp)
        end if
      end do
    end subroutine flush_pending_rest

    !> The step toward a stop: dt, or what is left when that is less. No sliver steps: a step
    !> that would end just short of the stop goes to it.
    real(wp) function step_toward(t_stop) result(h)
      real(wp), intent(in) :: t_stop
      real(wp) :: remaining
      remaining = (t_stop - s%t) - s%t_lo
      h = min(scene%dt, remaining)
      if (remaining - h <= 1.0e-9_wp * scene%dt) h = remaining
    end function step_toward

    !> Under constant forces the steps that end before every watched gap's and sliding body's
    !> quiet time (find_quiet_times) can meet no event: they need no location, and the ledger
    !> over them is the forces times the displacement. Their bulk is taken here in a tight
    !> loop, each step RK4's closed form under constant acceleration; the sums are compensated
    !> as in add_compensated but renormalised once at the end (the low parts carry the rounding
    !> meanwhile, and a position's increment reads its velocity's low part). The last steps
    !> before the stop follow step_toward, so the steps are those of the located path.
    subroutine glide(t_stop, at_stop)
      real(wp), intent(in) :: t_stop
      logical, intent(out) :: at_stop      !< the steps reached t_stop
      type(state_type) :: start
      real(wp) :: t_quiet, h, t, t_lo, x(2), x_lo(2), v(2), v_lo(2), dv(2), half_dv(2)
      integer(int64) :: n_bulk, n

      at_stop = .false.
      t_quiet = minval(quiet_until)
      if (s%t + step_toward(t_stop) >= t_quiet) return
      start = s
      ! Whole steps of dt ending at least a step short of the stop and the quiet time
      ! (capped where the count would not fit an integer: such a run never ends anyway).
      n_bulk = int(min(min((t_stop - s%t) - s%t_lo, t_quiet - s%t) / scene%dt, 1.0e18_wp), int64) - 1
      h = scene%dt
      dv = h * rk%constant_acceleration
      half_dv = 0.5_wp * dv
      t = s%t
      t_lo = s%t_lo
      x = s%x
      x_lo = s%x_lo
      v = s%v
      v_lo = s%v_lo
      do while (n_bulk > 0)
        ! In runs of up to the next progress report.
        n = min(n_bulk, 4096_int64 - iand(stats%steps, 4095_int64))
        call constant_steps(n, h, dv, half_dv, t, t_lo, x, x_lo, v, v_lo)
        n_bulk = n_bulk - n
        stats%steps = stats%steps + n
        if (iand(stats%steps, 4095_int64) == 0) call sink%progress(t, scene%t_end)
      end do
      call renormalise(t, t_lo)
      call renormalise(x, x_lo)
      call renormalise(v, v_lo)
      s%t = t
      s%t_lo = t_lo
      s%x = x
      s%x_lo = x_lo
      s%v = v
      s%v_lo = v_lo
      ! The last steps: to the stop by the step rule, while they stay quiet.
      do
        h = step_toward(t_stop)
        if (h <= 0.0_wp .or. s%t + h >= t_quiet) exit
        at_stop = h == (t_stop - s%t) - s%t_lo
        call rk%advance_constant(s, h)
        stats%steps = stats%steps + 1
        if (iand(stats%steps, 4095_int64) == 0) call sink%progress(s%t, scene%t_end)
        if (at_stop) then
          s%t = t_stop
          s%t_lo = 0.0_wp
          exit
        end if
      end do
      call book_constant_ledger(scene, mode, start, s)
      call check_finite()
    end subroutine glide

    subroutine check_finite()
      if (.not. finite_state(s)) call raise(error, status_simulation, 'at t = ' // fmt(s%t) // &
        ': the state is no longer finite')
    end subroutine check_finite




    !> Earliest event in (0, step]: a gap closing, a sliding body stopping, a mode condition
    !> failing. watched = k for contact k, 100 + i for body i, -1 for a mode condition.
    subroutine locate(a, b, step, theta, which)
      type(state_type), intent(in) :: a, b
      real(wp), intent(in) :: step
      real(wp), intent(out) :: theta
      integer, intent(out) :: which
      real(wp) :: c(3, 2), p(0:3), candidate, scale, acc_rounding(2)
      integer :: k, i
      logical :: have_dense, have_acc_rounding

      theta = huge(1.0_wp)
      which = 0
      have_dense = .false.
      have_acc_rounding = .false.
      do k = 1, n_contacts
        if (.not. scene%has_contact(k) .or. mode%active(k)) cycle
        if (a%t + step < quiet_until(k)) cycle
        if (.not. have_dense) c = dense_output(a, b, step)
        have_dense = .true.
        p(0) = gap(scene, k, a)
        p(1:3) = normal(1, k) * c(:, 1) + normal(2, k) * c(:, 2)
        ! The common case first: the gap cannot reach zero within the step.
        if (p(0) - step * (abs(p(1)) + step * (abs(p(2)) + step * abs(p(3)))) > 0.0_wp) cycle
        ! Only a gap that may close needs the forces' rounding (a sine costs two evaluations).
        if (.not. have_acc_rounding) acc_rounding = 1.0e3_wp * eps_wp * &
          force_scale(scene, scene%forcing%force(a%t), scene%forcing%rate(a%t)) / scene%mass
        have_acc_rounding = .true.
        candidate = earliest_crossing(p, step, gap_tolerance_along(scene, k, a, c, acc_rounding))
        if (candidate < theta) then
          theta = candidate
          which = k
        end if
      end do
      do i = 1, 2
        if (scene%friction(i) == 0.0_wp .or. mode%sgn(i) == 0.0_wp) cycle
        if (a%t + step < quiet_until(n_contacts + i)) cycle
        if (.not. have_dense) c = dense_output(a, b, step)
        have_dense = .true.
        ! Sliding velocity in its own direction: the derivative of the Hermite cubic.
        p = mode%sgn(i) * [c(1, i), 2.0_wp * c(2, i), 3.0_wp * c(3, i), 0.0_wp]
        scale = max(abs(a%v(i)), abs(b%v(i)), abs(b%v(i) - a%v(i)))
        candidate = earliest_crossing(p, step, [velocity_rounding * scale, 0.0_wp, 0.0_wp, 0.0_wp])
        if (candidate < theta) then
          theta = candidate
          which = 100 + i
        end if
      end do
      ! Under constant forces the mode's conditions are constant: they held when it began.
      if (mode%n_hold > 0 .and. .not. rk%constant_forcing) then
        candidate = hold_crossing(a%t, step)
        if (candidate < theta) then
          theta = candidate
          which = -1
        end if
      end if
    end subroutine locate


    !> Earliest time in [0, step] at which a condition of the mode (a contact force, a static
    !> friction margin) has turned negative. They depend on time only: linear within a step under
    !> piecewise-linear forcing, so the ends decide; a sine is sampled finer before bisection.
    real(wp) function hold_crossing(t0, step) result(theta)
      real(wp), intent(in) :: t0, step
      real(wp) :: lo, hi, mid, tol
      integer :: n_sub, j
      theta = huge(1.0_wp)
      tol = hold_tolerance(t0)
      n_sub = 1
      do j = 1, 2
        if (scene%forcing%has_sine(j)) n_sub = max(n_sub, &
          ceiling(16.0_wp * step * scene%forcing%omega(j) / (2.0_wp * acos(-1.0_wp))))
      end do
      lo = 0.0_wp
      do j = 1, n_sub
        hi = step * real(j, wp) / real(n_sub, wp)
        if (worst_hold(t0 + hi) < -tol) then
          ! Bisection to the first instant at which a condition has failed (within rounding):
          ! there the new mode's accelerations have the sign of the change. At the last
          ! instant that held, a released contact would be left a rounding-level acceleration
          ! back into it and close again at once, for ever.
          do while (hi - lo > 2.0_wp * eps_wp * max(abs(t0 + hi), step))
            mid = 0.5_wp * (lo + hi)
            if (worst_hold(t0 + mid) < 0.0_wp) then
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

    real(wp) function worst_hold(t)
      real(wp), intent(in) :: t
      real(wp) :: values(max_holds)
      values = mode%holds(scene%forcing%force(t))
      worst_hold = minval(values(1:mode%n_hold))
    end function worst_hold

    real(wp) function hold_tolerance(t)
      real(wp), intent(in) :: t
      hold_tolerance = 1.0e3_wp * eps_wp * force_scale(scene, scene%forcing%force(t), scene%forcing%rate(t)) &
        + tiny(1.0_wp)
    end function hold_tolerance


    !> Re-take the step to the located time and polish it by Newton's method on the watched
    !> function evaluated on the integrator's own state: under polynomial forcing the dense
    !> output is exact and the first check passes; under a sine it is approximate.
    subroutine refine(a, step, which, b)
      type(state_type), intent(in) :: a
      real(wp), intent(inout) :: step
      integer, intent(in) :: which
      type(state_type), intent(out) :: b
      real(wp) :: value, slope, tol, acc(2), located_step
      integer :: iteration
      located_step = step
      call rk%step(scene, mode, a, step, b)
      if (which <= 0) return
      do iteration = 1, 8
        if (which > 100) then
          value = b%v(which - 100)
          acc = mode%acceleration(scene%forcing%force(b%t))
          slope = acc(which - 100)
          tol = velocity_rounding * max(abs(a%v(which - 100)), abs(value))
        else
          value = gap(scene, which, b)
          slope = normal_velocity(which, b%v)
          tol = gap_tolerance(scene, which, b, displacement(which, a, b))
        end if
        if (abs(value) <= tol .or. slope == 0.0_wp) exit
        ! Newton stays inside the step that was located, or the clock could pass a stop.
        if (step - value / slope <= 0.0_wp .or. step - value / slope > located_step) exit
        step = step - value / slope
        call rk%step(scene, mode, a, step, b)
      end do
    end subroutine refine

    !> A gap that closed exactly at a stop (its root at the step's very end) with the bodies
    !> still approaching: the impact belongs to this instant, so the sample shows its result.
    logical function impact_due()
      integer :: k
      impact_due = .false.
      do k = 1, n_contacts
        if (.not. scene%has_contact(k) .or. mode%active(k)) cycle
        if (gap(scene, k, s) <= gap_tolerance(scene, k, s, 0.0_wp) .and. normal_velocity(k, s%v) < -u_tolerance(k)) &
          impact_due = .true.
      end do
    end function impact_due

    !> No step may end with a gap below zero beyond rounding, nor a sliding body past zero.
    !> The contact whose closing ended the step (located_contact) is put on its constraint at
    !> the event point, so its own rounding does not count.
    logical function constraints_hold(b, located_contact)
      type(state_type), intent(in) :: b
      integer, intent(in) :: located_contact
      integer :: k, i
      constraints_hold = .true.
      do k = 1, n_contacts
        if (.not. scene%has_contact(k) .or. mode%active(k) .or. k == located_contact) cycle
        if (gap(scene, k, b) < -gap_tolerance(scene, k, b, displacement(k, s, b))) constraints_hold = .false.
      end do
      do i = 1, 2
        if (scene%friction(i) == 0.0_wp .or. mode%sgn(i) == 0.0_wp) cycle
        if (mode%sgn(i) * b%v(i) < -velocity_rounding * max(abs(s%v(i)), abs(b%v(i)), &
            abs(b%v(i) - s%v(i)))) constraints_hold = .false.
      end do
    end function constraints_hold







    !> Everything that happens at one instant: closed contacts snapped, impacts resolved by
    !> sequential impulses, unresolvable bounce series put to rest (Zeno), stopped bodies
    !> zeroed, then the new mode from the complementarity problem, and the log of what changed.
    !> which: what the location found (contact k, 100 + body i, -1 a mode condition) or 0.
    subroutine event_point(initial, which)
      logical, intent(in) :: initial
      integer, intent(in) :: which
      logical :: closed(n_contacts), candidate(n_contacts), resting(2), found, leaving, resting_now
      logical :: pushed(n_contacts)
      real(wp) :: f(2), df(2), v_before(2), v_after(2), moving_sign(2), acc(2), tol_a(2), acc_rate(2)
      integer :: k, i, n_impulses
      type(mode_type) :: new_mode

      f = scene%forcing%force(s%t)
      df = scene%forcing%rate(s%t)
      do k = 1, n_contacts
        closed(k) = scene%has_contact(k)
        if (closed(k)) closed(k) = k == which .or. gap(scene, k, s) <= gap_tolerance(scene, k, s, 0.0_wp)
        ! The user's numbers carry their decimal rounding (7.553 - 7.122 is not 0.431): at the
        ! start, a gap within it is contact, as the validator accepted it.
        if (initial .and. scene%has_contact(k)) closed(k) = closed(k) .or. gap(scene, k, s) <= &
          gap_rounding * max(maxval(abs(normal(:, k) * s%x)), abs(scene%offset(k)))
      end do
      ! A rigid link (d_min = d_max) is one constraint seen from both sides.
      if (scene%has_contact(i_slot_min) .and. scene%has_contact(i_slot_max)) then
        if (scene%offset(i_slot_min) == -scene%offset(i_slot_max)) then
          closed(i_slot_min) = closed(i_slot_min) .or. closed(i_slot_max)
          closed(i_slot_max) = closed(i_slot_min)
        end if
      end if
      do k = 1, n_contacts
        if (closed(k)) call snap(scene, k, closed, s)
      end do
      ! A sliding body whose stop was located, or that stopped within rounding (its velocity
      ! change over a step is the scale), is at rest.
      acc = mode%acceleration(f)
      if (initial) acc = f / scene%mass     ! no mode yet: the free accelerations set the scale
      entry_scale = abs(s%v) + abs(acc) * scene%dt
      do i = 1, 2
        if (scene%friction(i) == 0.0_wp) cycle
        if (i == which - 100 .or. abs(s%v(i)) <= velocity_rounding * abs(acc(i)) * scene%dt) &
          call zero_velocity(i)
      end do

      ! Perfectly inelastic contacts closed together take one joint impact: sequential
      ! impulses would only approach it geometrically (a body pinned by a heavier one).
      if (joint_inelastic(scene, closed)) then
        v_before = s%v
        call inelastic_projection(scene, closed, s%v, u_tolerances(), v_after, pushed)
        if (any(pushed)) then
          call apply(v_after)
          if (any(pushed .and. [.false., .false., .true., .true.])) entry_scale = maxval(entry_scale)
          do k = 1, n_contacts
            if (pushed(k)) call log_event(event_impact + k, v_before, v_after)
          end do
        end if
      end if
      n_impulses = 0
      do
        k = most_approaching(closed, s%v, u_tolerances())
        if (k == 0) exit
        n_impulses = n_impulses + 1
        if (n_impulses > max_impulses) then
          call raise(error, status_simulation, 'at t = ' // fmt(s%t) // ': the impacts did not settle after ' &
            // fmt(max_impulses) // ' impulses')
          return
        end if
        v_before = s%v
        v_after = impulse(scene, k, restitution_of(scene, k, closed), s%v, rigid_pair(closed))
        call apply(v_after)
        if (all(normal(:, k) /= 0.0_wp)) entry_scale = maxval(entry_scale)
        call log_event(event_impact + k, v_before, v_after)
      end do

      ! Contacts left with a rounding-level normal velocity are closed and still.
      call zero_stopped(acc)
      do k = 1, n_contacts
        if (.not. closed(k)) cycle
        if (abs(normal_velocity(k, s%v)) <= u_tolerance(k) .and. normal_velocity(k, s%v) /= 0.0_wp) &
          call apply(impulse(scene, k, 0.0_wp, s%v, rigid_pair(closed)))
      end do

      ! Zeno: a bounce series whose remaining time is below the clock's resolution ends in
      ! rest now; the rest is logged at the series' accumulation time.
      do k = 1, n_contacts
        if (.not. closed(k)) cycle
        call bounce_series(k, f, df, closed)
        if (allocated(error)) return
      end do

      ! Impulses can leave a rounding-level velocity on a body that had stopped; it is zero.
      call zero_stopped(acc)
      ! A body still against the other one (a closed slot limit) that has stopped has stopped
      ! too: its velocity is the contact's rounding-level normal velocity.
      do k = 1, n_contacts
        if (.not. closed(k) .or. any(normal(:, k) == 0.0_wp)) cycle
        if (abs(normal_velocity(k, s%v)) > u_tolerance(k)) cycle
        do i = 1, 2
          if (s%v(i) == 0.0_wp) call zero_velocity(3 - i)
        end do
      end do

      call candidates(closed, candidate, resting, moving_sign)
      call solve_mode(scene, f, df, candidate, resting, moving_sign, new_mode, found, force_scale(scene, f, df))
      if (.not. found) then
        call raise(error, status_simulation, 'at t = ' // fmt(s%t) // &
          ': no consistent contact and friction state (complementarity problem has no solution)')
        return
      end if

      ! Log what a user can see change: contacts that start or stop holding, bodies that
      ! come to rest or break away.
      acc = new_mode%acceleration(f)
      tol_a = 1.0e3_wp * eps_wp * force_scale(scene, f, df) / scene%mass
      do k = 1, n_contacts
        if (new_mode%active(k) .and. .not. in_contact(k)) then
          call begin_rest(k, s%t)
        else if (in_contact(k) .and. .not. new_mode%active(k)) then
          if (.not. candidate(k) .or. dot_product(normal(:, k), acc) > dot_product(abs(normal(:, k)), tol_a) .or. &
              (dot_product(normal(:, k), acc) >= -dot_product(abs(normal(:, k)), tol_a) .and. &
              dot_product(normal(:, k), matmul(new_mode%gain, df)) > 1.0e3_wp * eps_wp * sum(abs(df)) / &
              minval(scene%mass))) then
            if (pending_rest(k) < huge(1.0_wp)) then
              call log_event(event_rest + k, s%v, s%v)
              pending_rest(k) = huge(1.0_wp)
            end if
            ! Logged once time has moved on: a contact that closes again at this same
            ! instant never opened (rounding-level relabelling), and neither entry is kept.
            in_contact(k) = .false.
            release_time(k) = s%t
            release_v(:, k) = s%v
          end if
        end if
      end do
      ! A body at rest leaves it when its acceleration, or at a break-away instant (force
      ! exactly at the bound) the acceleration's rate, points along its sliding direction.
      acc_rate = matmul(new_mode%gain, df)
      do i = 1, 2
        if (scene%friction(i) == 0.0_wp) cycle
        leaving = new_mode%sgn(i) * acc(i) > tol_a(i) .or. (new_mode%sgn(i) * acc(i) >= -tol_a(i) .and. &
          new_mode%sgn(i) * acc_rate(i) > 1.0e3_wp * eps_wp * sum(abs(df)) / scene%mass(i))
        resting_now = s%v(i) == 0.0_wp .and. .not. leaving
        ! A body that impulses moved off its rest and that stops again at that same instant
        ! (a chain of impacts ending there) never left rest: no stick (its leaving was not
        ! logged either).
        if (resting_now .and. .not. at_rest(i) .and. .not. initial .and. &
            .not. same_instant(scene, s%t, rest_lost_time(i))) call log_event(event_stick + i, s%v, s%v)
        if (.not. resting_now .and. at_rest(i)) then
          if (s%v(i) == 0.0_wp) then
            call log_event(event_slip + i, s%v, s%v)
          else
            rest_lost_time(i) = s%t
          end if
        end if
        at_rest(i) = resting_now
      end do
      mode = new_mode
      entry_scale = 0.0_wp
      quiet_until = -huge(1.0_wp)
      if (rk%constant_forcing) then
        rk%constant_acceleration = mode%acceleration(scene%forcing%constant)
        call find_quiet_times()
      end if
      watching = mode%n_hold > 0 .or. any(scene%has_contact .and. .not. mode%active) .or. &
        any(scene%friction > 0.0_wp .and. mode%sgn /= 0.0_wp)
    end subroutine event_point

    !> The bounce series on closed contact k, if its bodies separate slowly: gap acceleration
    !> while rising (a_up) and falling back (a_down) come from the mode with k left free, for
    !> the velocities now and with the normal velocity reversed (friction may change sides).
    !> Under constant forces each arc takes u/|a_up| + u/sqrt(a_up a_down) and the next impact
    !> speed is r u sqrt(a_down/a_up): the series is geometric and its sum is closed form.
    subroutine bounce_series(k, f, df, closed)
      integer, intent(in) :: k
      real(wp), intent(in) :: f(2), df(2)
      logical, intent(in) :: closed(n_contacts)
      real(wp) :: u, a_up, a_down, ratio, first_arc, remaining
      real(wp) :: r
      u = normal_velocity(k, s%v)
      if (u <= u_tolerance(k)) return
      a_up = free_gap_acceleration(k, s%v, f, df, closed)
      if (a_up >= 0.0_wp) return
      a_down = free_gap_acceleration(k, impulse(scene, k, 1.0_wp, s%v, rigid_pair(closed)), f, df, closed)
      r = restitution_of(scene, k, closed)
      remaining = huge(1.0_wp)
      if (a_down < 0.0_wp) then
        first_arc = u / (-a_up) + u / sqrt(a_up * a_down)
        ratio = r * sqrt(a_down / a_up)
        if (ratio < 1.0_wp) remaining = first_arc / (1.0_wp - ratio)
      end if
      ! Gaps are exact to their own size, so the series is followed until what remains of it
      ! is below the clock's resolution.
      if (remaining > time_rounding * max(abs(s%t), scene%dt)) return
      call apply(impulse(scene, k, 0.0_wp, s%v, rigid_pair(closed)))
      if (remaining < huge(1.0_wp)) then
        call begin_rest(k, s%t + remaining)
      else
        call begin_rest(k, s%t)
      end if
    end subroutine bounce_series

    !> Contact k starts to rest, logged at `when` (now, or a series' accumulation time).
    !> Nothing is logged if it already rests, or if it was released at this same instant.
    subroutine begin_rest(k, when)
      integer, intent(in) :: k
      real(wp), intent(in) :: when
      if (in_contact(k)) return
      in_contact(k) = .true.
      if (release_time(k) < huge(1.0_wp)) then
        if (same_instant(scene, s%t, release_time(k))) then
          release_time(k) = huge(1.0_wp)
          return
        end if
      end if
      ! Releases from earlier instants go first; one at this instant may still cancel.
      call flush_releases(.false.)
      if (when > s%t) then
        pending_rest(k) = when
      else
        call log_event(event_rest + k, s%v, s%v)
      end if
    end subroutine begin_rest


    !> Log the releases decided at an earlier instant (all of them with everything).
    subroutine flush_releases(everything)
      logical, intent(in) :: everything
      integer :: k
      do k = 1, n_contacts
        if (release_time(k) == huge(1.0_wp)) cycle
        if (.not. everything .and. same_instant(scene, s%t, release_time(k))) cycle
        stats%events(event_release + k) = stats%events(event_release + k) + 1
        call sink%put_event(release_time(k), event_release + k, release_v(:, k), release_v(:, k))
        release_time(k) = huge(1.0_wp)
      end do
    end subroutine flush_releases

    !> Under constant forces a mode's motion is an exact quadratic, so the first instant an
    !> open gap can close, or a sliding body can stop, is known in closed form; steps that end
    !> well before it (1% of the way, far beyond rounding) need no location for it. Only a
    !> shortcut: the location itself still finds the event.
    subroutine find_quiet_times()
      integer :: k, i
      quiet_until = huge(1.0_wp)     ! what is not watched needs no location
      do k = 1, n_contacts
        if (.not. scene%has_contact(k) .or. mode%active(k)) cycle
        quiet_until(k) = s%t + 0.99_wp * first_negative(gap(scene, k, s), normal_velocity(k, s%v), &
          dot_product(normal(:, k), rk%constant_acceleration))
      end do
      do i = 1, 2
        if (scene%friction(i) == 0.0_wp .or. mode%sgn(i) == 0.0_wp) cycle
        quiet_until(n_contacts + i) = s%t + 0.99_wp * first_negative(mode%sgn(i) * s%v(i), &
          mode%sgn(i) * rk%constant_acceleration(i), 0.0_wp)
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


    !> Normal acceleration of contact k with k left free and the others as they are.
    real(wp) function free_gap_acceleration(k, v, f, df, closed) result(a_gap)
      integer, intent(in) :: k
      real(wp), intent(in) :: v(2), f(2), df(2)
      logical, intent(in) :: closed(n_contacts)
      type(mode_type) :: free_mode
      logical :: candidate(n_contacts), resting(2), found
      real(wp) :: moving_sign(2), v_saved(2)
      v_saved = s%v
      s%v = v
      call candidates(closed, candidate, resting, moving_sign)
      s%v = v_saved
      candidate(k) = .false.
      call solve_mode(scene, f, df, candidate, resting, moving_sign, free_mode, found, force_scale(scene, f, df))
      a_gap = 0.0_wp
      if (found) a_gap = dot_product(normal(:, k), free_mode%acceleration(f))
    end function free_gap_acceleration

    !> Bodies whose velocity is below the rounding of what a step changes it by, or of the
    !> velocities this event point started from, are at rest.
    subroutine zero_stopped(acc)
      real(wp), intent(in) :: acc(2)
      integer :: i
      do i = 1, 2
        if (s%v(i) /= 0.0_wp .and. abs(s%v(i)) <= velocity_rounding * max(abs(acc(i)) * scene%dt, &
            entry_scale(i))) call zero_velocity(i)
      end do
    end subroutine zero_stopped

    !> Body i is at rest; the rounding-level energy it had goes to the impact loss.
    subroutine zero_velocity(i)
      integer, intent(in) :: i
      s%impact_loss = s%impact_loss + 0.5_wp * scene%mass(i) * s%v(i)**2
      s%v(i) = 0.0_wp
      s%v_lo(i) = 0.0_wp
    end subroutine zero_velocity

    !> Set new velocities at an instant, booking the kinetic energy they remove as impact loss.
    subroutine apply(v_new)
      real(wp), intent(in) :: v_new(2)
      s%impact_loss = s%impact_loss + kinetic_energy(scene, s%v) - kinetic_energy(scene, v_new)
      s%v = v_new
      s%v_lo = 0.0_wp
    end subroutine apply

    !> The complementarity problem's unknowns at this instant.
    subroutine candidates(closed, candidate, resting, moving_sign)
      logical, intent(in) :: closed(n_contacts)
      logical, intent(out) :: candidate(n_contacts), resting(2)
      real(wp), intent(out) :: moving_sign(2)
      integer :: k
      do k = 1, n_contacts
        candidate(k) = closed(k)
        if (candidate(k)) candidate(k) = abs(normal_velocity(k, s%v)) <= u_tolerance(k)
      end do
      resting = scene%friction > 0.0_wp .and. s%v == 0.0_wp
      moving_sign = 0.0_wp
      where (scene%friction > 0.0_wp .and. s%v /= 0.0_wp) moving_sign = sign(1.0_wp, s%v)
    end subroutine candidates

    !> Rounding level of contact k's normal velocity: from the speeds of the bodies it
    !> involves and what a step changes them by, so a slow body is not judged by a fast one.
    real(wp) function u_tolerance(k)
      integer, intent(in) :: k
      real(wp) :: acc(2)
      acc = mode%acceleration(scene%forcing%force(s%t))
      u_tolerance = velocity_rounding * dot_product(abs(normal(:, k)), &
        max(abs(s%v) + abs(acc) * scene%dt, entry_scale))
    end function u_tolerance

    function u_tolerances() result(tol)
      real(wp) :: tol(n_contacts)
      integer :: k
      tol = [(u_tolerance(k), k = 1, n_contacts)]
    end function u_tolerances




  end subroutine run
end module impact1d_solver

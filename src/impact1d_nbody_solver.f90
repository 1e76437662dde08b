!> The engine's driver (docs/method.md section 9), for any number of bodies: the method on
!> N-long arrays. From the current state it picks the next stop (sample time, table corner
!> or pending rest), takes the steps before the mode's quiet time in closed form under
!> constant forces or tables (impact1d_nbody_glide), then one RK4 step toward it, locates the earliest
!> event inside the step on the dense output (impact1d_nbody_step), re-takes the step to it,
!> and calls the event point (impact1d_nbody_event); samples go to the sink at sample times. impact1d_solver's
!> run hands every scene of the event method here.
module impact1d_nbody_solver
  use, intrinsic :: iso_fortran_env, only: int64
  use impact1d_kinds, only: wp
  use impact1d_error, only: error_type, raise, status_simulation, fmt
  use impact1d_scene, only: scene_type, sample_time, step_length
  use impact1d_state, only: state_type, new_state, take_state, finite_state
  use impact1d_output, only: sink_type, run_stats, emit_bodies, checkpoint
  use impact1d_event_log, only: event_log_type
  use impact1d_yardsticks, only: velocity_rounding
  use impact1d_elements, only: element_potential, stop_potential
  use impact1d_body_mode, only: body_mode_type, new_mode
  use impact1d_nbody_step, only: nbody_step, nbody_force, locate_nbody, refine_nbody, gaps_hold, row_gap, &
    row_velocity, row_gap_tolerance, found_none, found_row, kept_forces_type, clock_to_stop, &
    clock_to_belts
  use impact1d_nbody_event, only: point_work_type, new_point_work, nbody_event_point
  use impact1d_nbody_glide, only: glide_type, new_glide, find_quiet_time, glide
  implicit none
  private
  public :: run_nbody

  integer, parameter :: max_halvings = 60        !< retries of a step whose end violated a constraint

  !> What the run owns besides its state: the mode, the event point's memory, the log.
  type :: nbody_run_type
    type(body_mode_type) :: mode
    type(point_work_type) :: work
    type(event_log_type) :: event_log
    !> The last step's end forces, for the next step's first stage (nbody_step).
    type(kept_forces_type) :: kept
    !> Tables and constants only: the dense output is exact, so no root can be missed.
    logical :: polynomial = .false.
    real(wp) :: ke0 = 0.0_wp, pe0 = 0.0_wp
    !> Constant forces or tables: the steps before the mode's quiet time without location.
    type(glide_type) :: glide
  end type nbody_run_type

contains

  !> Run an N-body scene from t = 0 to t_end, every dt_out sample and every event to sink.
  subroutine run_nbody(scene, sink, stats, error, closed_form)
    type(scene_type), intent(in) :: scene
    class(sink_type), intent(inout) :: sink
    type(run_stats), intent(inout) :: stats
    type(error_type), allocatable, intent(inout) :: error
    !> .false.: every step taken with its location, none in closed form (tests compare the
    !> two: the same bits); default .true.
    logical, intent(in), optional :: closed_form
    type(state_type) :: s, trial
    type(nbody_run_type) :: r
    real(wp) :: sample_t, t_break, t_rest, t_stop, window_start
    integer :: j_sample, found, index, window_events
    logical :: at_stop, event_due

    call start(scene, s, trial, r)
    if (present(closed_form)) r%glide%able = r%glide%able .and. closed_form
    call nbody_event_point(scene, .true., found_none, 0, s, r%mode, r%event_log, r%work, sink, stats, error)
    if (allocated(error)) return
    call find_quiet_time(scene, r%mode, r%work%mode, s, r%glide)
    j_sample = 0
    call emit(scene, s, r, j_sample, sink, stats, error)
    if (allocated(error)) return
    window_events = 0
    window_start = 0.0_wp
    t_break = min(scene%forcing%next_breakpoint(s%t), scene%drives%next_corner(s%t))
    t_rest = next_rest(scene, r)
    do while (j_sample < scene%n_samples)
      sample_t = sample_time(scene, j_sample)
      if (t_break <= s%t) t_break = min(scene%forcing%next_breakpoint(s%t), scene%drives%next_corner(s%t))
      t_stop = min(sample_t, t_break, t_rest)
      ! The steps that can meet no event in closed form; then one located step (advance).
      at_stop = .false.
      if (r%glide%able) call glide(scene, r%mode, r%glide, t_stop, s, trial, r%kept, at_stop, sink, stats, error)
      if (allocated(error)) return
      found = found_none
      index = 0
      if (.not. at_stop) then
        r%glide%fixed = .false.
        call advance(scene, r, t_stop, s, trial, found, index, at_stop, sink, stats, error)
      end if
      if (allocated(error)) return
      event_due = found /= found_none
      if (.not. event_due .and. at_stop) event_due = t_stop == t_break .or. t_stop == t_rest .or. &
        impact_due(scene, s)
      if (event_due) then
        ! Work is bounded per step of simulated time (the two-body engine's rule).
        if (s%t - window_start >= scene%dt) then
          window_start = s%t
          window_events = 0
        end if
        window_events = window_events + 1
        if (window_events > scene%max_step_events) then
          call raise(error, status_simulation, 'at t = ' // trim(fmt(s%t)) // ': more than ' // &
            trim(fmt(scene%max_step_events)) // ' events within one step (dt = ' // trim(fmt(scene%dt)) // &
            '): the contacts chatter faster than the run can follow (lower a restitution near 1 on a ' // &
            'contact pressed shut, or raise &run max_step_events)')
          return
        end if
        call r%event_log%flush_releases(scene, s%t, .false., sink, stats)
        call r%event_log%flush_pending_rest(scene, s%t, s%v, sink, stats)
        call nbody_event_point(scene, .false., found, index, s, r%mode, r%event_log, r%work, sink, stats, error)
        if (allocated(error)) return
        call r%kept%forget()
        call find_quiet_time(scene, r%mode, r%work%mode, s, r%glide)
        t_rest = next_rest(scene, r)
      end if
      if (at_stop .and. s%t == sample_t) then
        call emit(scene, s, r, j_sample, sink, stats, error)
        if (allocated(error)) return
      end if
    end do
    call r%event_log%flush_releases(scene, s%t, .true., sink, stats)
    call sink%end_progress()
  end subroutine run_nbody

  !> The run's memory, once (nothing allocates per step), and its start.
  subroutine start(scene, s, trial, r)
    type(scene_type), intent(in) :: scene
    type(state_type), intent(inout) :: s, trial
    type(nbody_run_type), intent(inout) :: r
    call new_state(scene%n_bodies, s)
    call new_state(scene%n_bodies, trial)
    s%x = scene%body_x0
    s%v = scene%body_v0
    call new_mode(scene%n_bodies, scene%n_rows, r%mode, r%work%mode)
    ! The compliant stops, none engaged (a scene starts outside every limit).
    if (scene%n_stops > 0) then
      allocate(r%mode%engaged(scene%n_stops))
      r%mode%engaged = .false.
    end if
    call new_point_work(scene%n_bodies, r%work)
    call r%kept%reserve(scene%n_bodies, .not. scene%forcing%varies)
    call new_glide(scene, r%glide)
    call r%event_log%allocate_log(scene%n_rows, scene%n_bodies)
    r%polynomial = scene%forcing%is_polynomial() .and. .not. scene%springs%present .and. scene%drives%polynomial &
      .and. .not. scene%stribeck .and. .not. scene%belt_moves
    r%ke0 = 0.5_wp * dot_product(scene%body_mass, s%v**2)
    r%pe0 = potential(scene, s)
  end subroutine start

  !> The earliest rest pending at an accumulation time (huge: none). Only the event point
  !> and flush_pending_rest change them: formed after them, not every step.
  pure real(wp) function next_rest(scene, r) result(t_rest)
    type(scene_type), intent(in) :: scene
    type(nbody_run_type), intent(in) :: r
    t_rest = huge(1.0_wp)
    if (scene%n_rows > 0) t_rest = minval(r%event_log%pending_rest)
  end function next_rest

  !> Sample j_sample (then the next one is due).
  subroutine emit(scene, s, r, j_sample, sink, stats, error)
    type(scene_type), intent(in) :: scene
    type(state_type), intent(in) :: s
    type(nbody_run_type), intent(in) :: r
    integer, intent(inout) :: j_sample
    class(sink_type), intent(inout) :: sink
    type(run_stats), intent(inout) :: stats
    type(error_type), allocatable, intent(inout) :: error
    if (scene%drives%n > 0 .or. scene%belts) then
      call emit_bodies(sink, stats, s%t, s%x, s%v, scene%body_mass, r%ke0, s%work, s%friction_loss, &
        s%impact_loss, scene%springs%present, [potential(scene, s), r%pe0, s%damping_loss], error, s%drive_work)
    else
      call emit_bodies(sink, stats, s%t, s%x, s%v, scene%body_mass, r%ke0, s%work, s%friction_loss, &
        s%impact_loss, scene%springs%present, [potential(scene, s), r%pe0, s%damping_loss], error)
    end if
    j_sample = j_sample + 1
  end subroutine emit

  !> The springs' potential energy in state s (moving ground ends where they are at s%t).
  pure real(wp) function potential(scene, s) result(pe)
    type(scene_type), intent(in) :: scene
    type(state_type), intent(in) :: s
    pe = 0.0_wp
    if (.not. scene%springs%present) return
    if (scene%gap_terms) then
      pe = element_potential(scene, s%x, s%x_lo, s%t)
    else
      pe = element_potential(scene, s%x, s%x_lo)
    end if
    if (scene%n_stops > 0) pe = pe + stop_potential(scene, s%x, s%x_lo, s%t)
  end function potential

  !> One step from s toward t_stop, ended at the earliest event located in it (found, index)
  !> or at the stop (at_stop). A step whose end breaks a constraint (a root the location
  !> missed: forcing that is not polynomial only) is retried shorter.
  subroutine advance(scene, r, t_stop, s, trial, found, index, at_stop, sink, stats, error)
    type(scene_type), intent(in) :: scene
    type(nbody_run_type), intent(inout) :: r
    real(wp), intent(in) :: t_stop
    type(state_type), intent(inout) :: s, trial
    integer, intent(out) :: found, index
    logical, intent(out) :: at_stop
    class(sink_type), intent(inout) :: sink
    type(run_stats), intent(inout) :: stats
    type(error_type), allocatable, intent(inout) :: error
    real(wp) :: h, theta, h_taken
    integer :: halvings
    h = step_length(scene%dt, (t_stop - s%t) - s%t_lo)
    halvings = 0
    do
      found = found_none
      index = 0
      if (h <= 0.0_wp) then
        trial = s
        call r%kept%forget()
        exit
      end if
      call nbody_step(scene, r%mode, s, h, trial, r%kept)
      call locate_nbody(scene, r%mode, r%work%mode, r%polynomial, s, trial, h, r%kept, theta, found, index)
      if (found /= found_none .and. theta <= h) then
        h_taken = h
        h = theta
        if (h > 0.0_wp) then
          call refine_nbody(scene, r%mode, r%polynomial, s, h, found, index, trial, r%kept, h_taken)
        else
          trial = s
          call r%kept%forget()
          exit
        end if
      else
        found = found_none
      end if
      if (r%polynomial) exit
      if (gaps_hold(scene, r%mode, s, trial, merge(index, 0, found == found_row))) exit
      halvings = halvings + 1
      if (halvings > max_halvings) then
        call raise(error, status_simulation, 'at t = ' // trim(fmt(s%t)) // &
          ': no step keeps the constraints (event location failed)')
        return
      end if
      h = 0.5_wp * h
    end do
    at_stop = found == found_none .and. h == (t_stop - s%t) - s%t_lo
    call take_state(s, trial)
    call r%kept%accept()
    if (at_stop) then
      ! (the stuck bodies on accelerating belts first: moved from the clock as it was)
      if (scene%belt_moves) call clock_to_belts(scene, r%mode, t_stop, s)
      call clock_to_stop(scene, r%mode, t_stop, s)
    end if
    stats%steps = stats%steps + 1
    if (iand(stats%steps, 4095_int64) == 0) then
      call checkpoint(sink, stats, s%t, scene%t_end, error)
      if (allocated(error)) return
    end if
    if (.not. finite_state(s%x, s%v, s%work)) call raise(error, status_simulation, 'at t = ' // &
      trim(fmt(s%t)) // ': the state is no longer finite')
  end subroutine advance

  !> A gap that closed exactly at a stop (its root at the step's very end) with its ends
  !> still approaching: the impact belongs to this instant.
  logical function impact_due(scene, s)
    type(scene_type), intent(in) :: scene
    type(state_type), intent(in) :: s
    integer :: k
    real(wp) :: speed
    impact_due = .false.
    do k = 1, scene%n_rows
      if (row_gap(scene, k, s) > row_gap_tolerance(scene, k, s, 0.0_wp)) cycle
      speed = abs(s%v(scene%row_body(2, k)))
      if (scene%row_body(1, k) > 0) speed = speed + abs(s%v(scene%row_body(1, k)))
      if (row_velocity(scene, k, s%v, s%t) < -velocity_rounding * speed) impact_due = .true.
    end do
  end function impact_due
end module impact1d_nbody_solver

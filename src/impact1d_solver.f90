!> The hybrid-system driver (METHOD.md sections 2-6): classical RK4 at the user's step
!> within a mode, in-step location of the earliest event on the step's dense output, a
!> re-step to the event time, then impacts, Zeno rest and a new mode at the event point.
!> Nothing here allocates, formats or writes per step; output goes to a sink at sample times.
!> The stages live in their own modules (docs/architecture.md): impact1d_state,
!> impact1d_yardsticks, impact1d_contacts, impact1d_stepping, impact1d_location,
!> impact1d_event_log and impact1d_event_point; this module only drives them.
module impact1d_solver
  use, intrinsic :: iso_fortran_env, only: int64
  use impact1d_kinds, only: wp
  use impact1d_error, only: error_type, raise, status_simulation, fmt
  use impact1d_scene, only: scene_type, sample_time, step_length, runs_nbody
  use impact1d_modes, only: mode_type
  use impact1d_impacts, only: normal_velocity, kinetic_energy
  use impact1d_output, only: sink_type, run_stats, emit_sample, checkpoint, start_counts
  use impact1d_vissim, only: run_vissim
  use impact1d_interrupt, only: interrupt_count
  use impact1d_state, only: state_type, lane_state_type, load_lanes, new_state, renormalise, &
    finite_state, constant_step, constant_steps, add_compensated
  use impact1d_lanes, only: max_lanes, to_lanes
  use impact1d_contacts, only: gap, gap_tolerance, u_tolerance
  use impact1d_stepping, only: rk4_type, book_constant_ledger, books_ledger
  use impact1d_location, only: watch_type, refine, constraints_hold, located_type, located_row
  use impact1d_event_log, only: event_log_type
  use impact1d_event_point, only: event_point
  use impact1d_nbody_solver, only: run_nbody
  use impact1d_loads, only: stop_potential
  implicit none
  private
  public :: run, run_stats

  integer, parameter :: max_halvings = 60        !< retries of a step whose end violated a constraint

  !> Where the run stops next: the next sample (its index and time), the next table corner
  !> and the earliest pending accumulation time; a step goes no further than the first.
  type :: stops_type
    integer :: j_sample = 0
    real(wp) :: sample_t = 0.0_wp, t_break = 0.0_wp, t_rest = huge(1.0_wp)
  end type stops_type

contains

  !> Run a scene from t = 0 to t_end, sending every dt_out sample and every event to sink
  !> (with method 'vissim', the tutorial's fixed-step scheme instead).
  subroutine run(scene, sink, stats, error, interrupt_epoch)
    type(scene_type), intent(in) :: scene
    class(sink_type), intent(inout) :: sink
    type(run_stats), intent(out) :: stats
    type(error_type), allocatable, intent(out) :: error
    !> The interrupt count its caller started with (a sweep's, for every run of it: a run
    !> its worker starts after the interrupt ends at its first checkpoint); absent or
    !> negative: the count now.
    integer, intent(in), optional :: interrupt_epoch

    ! The run's state: N long as the model (its start, s0), in lanes from then on (s). While
    ! N <= max_lanes the whole run keeps it in lanes: loading it into lanes and storing it
    ! back at every step and event point cost ~10% of a spring step (docs/performance.md).
    type(state_type) :: s0
    type(lane_state_type) :: s
    type(lane_state_type) :: trial   ! advance's scratch (declared here: a local would be default-initialised every step)
    type(mode_type) :: mode
    type(rk4_type) :: rk
    type(watch_type) :: watch
    type(event_log_type) :: event_log
    type(stops_type) :: stops
    real(wp) :: ke0, pe0, t_stop, window_start, x0(max_lanes)
    logical :: located, at_stop, glided, event_due
    type(located_type) :: watched
    integer :: window_events

    stats%interrupt_epoch = interrupt_count()
    if (present(interrupt_epoch)) then
      if (interrupt_epoch >= 0) stats%interrupt_epoch = interrupt_epoch
    end if
    ! What the sink calls the events on each row; nothing counted yet.
    sink%row_names = scene%row_name
    ! (a friction contact's events are named after it: impact1d_output's class_pair_stick)
    if (scene%n_frictions > 0) sink%row_names = [scene%row_name, scene%friction_name]
    call start_counts(stats, scene%n_rows + scene%n_stops, scene%n_bodies, scene%n_frictions)
    ! The tutorial's scheme, for any number of bodies (build_scene refuses it moving grounds
    ! and the friction laws). The stepping kernels here take the bodies in lanes
    ! (impact1d_lanes); more bodies, and scenes with a moving ground, a friction law
    ! (belt_v, v_s, c_v) or friction between bodies (&friction), run on the N-body engine.
    if (scene%method == 'vissim') then
      call run_vissim(scene, sink, stats, error)
      return
    end if
    if (runs_nbody(scene)) then
      call run_nbody(scene, sink, stats, error)
      return
    end if
    ! Springs and dampers make the forces depend on the state: no closed forms then.
    rk%polynomial_forcing = scene%forcing%is_polynomial() .and. .not. scene%springs%present
    rk%bulk_steps => constant_steps
    rk%constant_forcing = .not. (scene%forcing%varies .or. scene%springs%present)
    call rk%set_springs(scene, 0)
    ! Every array of the run, once: nothing allocates per step.
    call new_state(scene%n_bodies, s0)
    allocate(watch%quiet_body(scene%n_bodies))
    call event_log%allocate_log(scene%n_rows + scene%n_stops, scene%n_bodies)
    s0%x(:) = scene%body_x0
    s0%v(:) = scene%body_v0
    ke0 = kinetic_energy(scene, s0%v)
    call load_lanes(s0, s)
    pe0 = 0.0_wp
    call to_lanes(scene%body_x0, x0)
    if (scene%springs%present) pe0 = scene%springs%potential(x0, [0.0_wp, 0.0_wp])
    window_events = 0
    window_start = 0.0_wp

    call event_point(scene, .true., located_type(), s, mode, event_log, watch, rk, sink, stats, error)
    if (allocated(error)) return
    call emit(scene, s, ke0, pe0, stops%j_sample, sink, stats, error)
    if (allocated(error)) return

    stops%t_break = scene%forcing%next_breakpoint(s%t)
    do while (stops%j_sample < scene%n_samples)
      ! Step: to the next sample, table corner or accumulation time, whichever is first.
      stops%sample_t = sample_time(scene, stops%j_sample)
      if (stops%t_break <= s%t) stops%t_break = scene%forcing%next_breakpoint(s%t)
      stops%t_rest = minval(event_log%pending_rest)

      located = .false.
      glided = .false.
      if (rk%constant_forcing) then
        call glide(scene, mode, rk, watch, ke0, pe0, stops, s, sink, stats, glided, error)
        if (allocated(error)) return
      end if
      t_stop = min(stops%sample_t, stops%t_break, stops%t_rest)
      at_stop = glided
      if (.not. at_stop) then
        ! Locate and re-step: one step toward the stop, cut at the earliest event in it.
        call advance(scene, mode, rk, watch, t_stop, s, trial, located, watched, at_stop, sink, stats, error)
        if (allocated(error)) return
      end if

      ! Events, table corners (the force's slope changes) and accumulation times need an
      ! event point; a sample time does not.
      event_due = located
      if (.not. event_due .and. at_stop) event_due = t_stop == stops%t_break .or. t_stop == stops%t_rest
      ! A stop reached by quiet steps has no gap near closing.
      if (.not. event_due .and. at_stop .and. .not. glided) event_due = impact_due(scene, mode, s)
      if (event_due) then
        ! Work is bounded per step of simulated time, not per run: a long run may have
        ! millions of events, but events crowding one step (chatter at one instant, or an
        ! elastic bounce below the scene's resolution) mean the run no longer advances.
        if (s%t - window_start >= scene%dt) then
          window_start = s%t
          window_events = 0
        end if
        window_events = window_events + 1
        if (window_events > scene%max_step_events) then
          call raise(error, status_simulation, 'at t = ' // trim(fmt(s%t)) // ': more than ' // &
            trim(fmt(scene%max_step_events)) // ' events within one step (dt = ' // trim(fmt(scene%dt)) // &
            '): the contacts chatter faster than the run can follow (typically a contact with ' // &
            'restitution at or near 1 pressed shut, whose bounces never die out: lower that ' // &
            'restitution, or raise &run max_step_events)')
          return
        end if
        call event_log%flush_releases(scene, s%t, .false., sink, stats)
        call event_log%flush_pending_rest(scene, s%t, s%v(:scene%n_bodies), sink, stats)
        ! The event point: impacts, rest, the new mode, the log.
        call event_point(scene, .false., merge(watched, located_type(), located), s, mode, event_log, watch, rk, &
          sink, stats, error)
        if (allocated(error)) return
      end if
      ! Emit.
      if (at_stop .and. s%t == stops%sample_t) then
        call emit(scene, s, ke0, pe0, stops%j_sample, sink, stats, error)
        if (allocated(error)) return
      end if
    end do
    call event_log%flush_releases(scene, s%t, .true., sink, stats)
    call sink%end_progress()
  end subroutine run

  !> Sample j_sample of the run (then the next one is due); a row that is not finite is an error.
  subroutine emit(scene, s, ke0, pe0, j_sample, sink, stats, error)
    type(scene_type), intent(in) :: scene
    type(lane_state_type), intent(in) :: s
    real(wp), intent(in) :: ke0, pe0
    integer, intent(inout) :: j_sample
    class(sink_type), intent(inout) :: sink
    type(run_stats), intent(inout) :: stats
    type(error_type), allocatable, intent(out) :: error
    real(wp) :: pe
    pe = 0.0_wp
    if (scene%springs%present) pe = scene%springs%potential(s%x, s%x_lo)
    if (scene%n_stops > 0) pe = pe + stop_potential(scene, s%x, s%x_lo)
    call emit_sample(sink, stats, s%t, s%x, s%v, scene%pair%mass, ke0, s%work, s%friction_loss, &
      s%impact_loss, scene%springs%present, [pe, pe0, s%damping_loss], error)
    j_sample = j_sample + 1
  end subroutine emit

  !> One step from s toward t_stop, ended at the earliest event located in it (located,
  !> watched: what it found) or at the stop (at_stop). A step whose end breaks a constraint
  !> (a root the location missed: only possible for non-polynomial forcing) is retried shorter.
  subroutine advance(scene, mode, rk, watch, t_stop, s, trial, located, watched, at_stop, sink, stats, error)
    type(scene_type), intent(in) :: scene
    type(mode_type), intent(in) :: mode
    type(rk4_type), intent(inout) :: rk
    type(watch_type), intent(in) :: watch
    real(wp), intent(in) :: t_stop
    type(lane_state_type), intent(inout) :: s
    type(lane_state_type), intent(inout) :: trial   !< scratch: the step's end (inout: no default init)
    logical, intent(out) :: located, at_stop
    type(located_type), intent(out) :: watched
    class(sink_type), intent(inout) :: sink
    type(run_stats), intent(inout) :: stats
    type(error_type), allocatable, intent(inout) :: error
    real(wp) :: h, h_event, h_taken
    integer :: halvings

    h = step_toward(scene, s, t_stop)
    halvings = 0
    do
      located = .false.
      watched = located_type()
      ! An event that landed exactly on the stop leaves nothing to step.
      if (h <= 0.0_wp) then
        trial = s
        exit
      end if
      call rk%step(scene, mode, s, h, trial)
      if (.not. watch%watching) exit      ! nothing in this mode can end it: no location needed
      call watch%locate(scene, mode, rk%constant_forcing, rk%polynomial_forcing, s, trial, h, h_event, watched)
      located = h_event <= h
      if (located) then
        h_taken = h
        h = h_event
        if (h > 0.0_wp) then
          call refine(rk, scene, mode, s, h, watched, trial, h_taken)
        else
          trial = s     ! the event is at the step's start: nothing to step
          exit
        end if
      end if
      ! Under polynomial forcing the dense output is exact and nothing can be missed; only
      ! a sine's approximate dense output needs the step's end checked.
      if (rk%polynomial_forcing) exit
      if (constraints_hold(scene, mode, s, trial, merge(watched%index, 0, located .and. watched%kind == located_row))) exit
      halvings = halvings + 1
      if (halvings > max_halvings) then
        call raise(error, status_simulation, 'at t = ' // trim(fmt(s%t)) // &
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
    if (iand(stats%steps, 4095_int64) == 0) then
      call checkpoint(sink, stats, s%t, scene%t_end, error)
      if (allocated(error)) return
    end if
    call check_finite(s, error)
  end subroutine advance

  !> The step toward a stop: dt, or what is left when that is less. No sliver steps: a step
  !> that would end just short of the stop goes to it.
  pure real(wp) function step_toward(scene, s, t_stop) result(h)
    type(scene_type), intent(in) :: scene
    type(lane_state_type), intent(in) :: s
    real(wp), intent(in) :: t_stop
    h = step_length(scene%dt, (t_stop - s%t) - s%t_lo)
  end function step_toward

  !> A stop that is a sample and nothing else (no table corner, no accumulation time, not
  !> the run's last sample, which run takes): glide takes its sample and goes on.
  pure logical function quiet_sample(scene, stops, t_stop)
    type(scene_type), intent(in) :: scene
    type(stops_type), intent(in) :: stops
    real(wp), intent(in) :: t_stop
    quiet_sample = .true.
    if (t_stop /= stops%sample_t .or. t_stop == stops%t_break .or. t_stop == stops%t_rest .or. &
      stops%j_sample >= scene%n_samples - 1) quiet_sample = .false.
  end function quiet_sample

  !> Under constant forces the steps that end before every watched gap's and sliding body's
  !> quiet time (watch%find_quiet_times) can meet no event: they need no location, and the
  !> ledger over them is the forces times the displacement. Their bulk is taken in a tight
  !> loop (constant_steps), each step RK4's closed form under constant acceleration; the sums
  !> are compensated as in add_compensated but renormalised once at the end (the low parts
  !> carry the rounding meanwhile, and a position's increment reads its velocity's low
  !> part). The last steps before the stop follow step_toward, so the steps are those of the
  !> located path. A sample stop that is neither a table corner nor an accumulation time
  !> needs nothing but its sample: it is emitted here and the glide goes on to the next
  !> stop rather than going back through run's loop for each; the arithmetic is the same
  !> either way.
  subroutine glide(scene, mode, rk, watch, ke0, pe0, stops, ls, sink, stats, at_stop, error)
    type(scene_type), intent(in) :: scene
    type(mode_type), intent(in) :: mode
    type(rk4_type), intent(in) :: rk
    type(watch_type), intent(in) :: watch
    real(wp), intent(in) :: ke0, pe0
    type(stops_type), intent(inout) :: stops
    type(lane_state_type), intent(inout) :: ls
    class(sink_type), intent(inout) :: sink
    type(run_stats), intent(inout) :: stats
    logical, intent(out) :: at_stop      !< the steps reached the stop (stops say which)
    type(error_type), allocatable, intent(inout) :: error
    real(wp) :: t_quiet, t_stop, h, x_start(max_lanes), x_lo_start(max_lanes)
    integer(int64) :: n_bulk

    at_stop = .false.
    t_quiet = watch%quiet_time()
    ! Samples a step apart take a loop of their own.
    call step_to_samples(scene, mode, rk, t_quiet, ke0, pe0, stops, ls, sink, stats, error)
    if (allocated(error)) return
    do
      at_stop = .false.
      t_stop = min(stops%sample_t, stops%t_break, stops%t_rest)
      if (ls%t + step_length(scene%dt, (t_stop - ls%t) - ls%t_lo) >= t_quiet) exit
      x_start = ls%x
      x_lo_start = ls%x_lo
      ! Whole steps of dt ending at least a step short of the stop and the quiet time
      ! (capped where the count would not fit an integer: such a run never ends anyway).
      ! No bulk for a stop within two steps, as with a sample every step (the state is left
      ! as it is: renormalising an already normalised sum changes no bit); below 1.5 steps
      ! the count is 0 without the division.
      n_bulk = 0
      if ((t_stop - ls%t) - ls%t_lo >= 1.5_wp * scene%dt) n_bulk = &
        int(min(min((t_stop - ls%t) - ls%t_lo, t_quiet - ls%t) / scene%dt, 1.0e18_wp), int64) - 1
      if (n_bulk > 0) call bulk_steps(scene, rk, n_bulk, ls, sink, stats, error)
      if (allocated(error)) exit       ! (an interrupt: the run ends here)
      ! The last steps: to the stop by the step rule, while they stay quiet.
      do
        h = step_length(scene%dt, (t_stop - ls%t) - ls%t_lo)
        if (h <= 0.0_wp .or. ls%t + h >= t_quiet) exit
        at_stop = h == (t_stop - ls%t) - ls%t_lo
        call add_compensated(ls%t, ls%t_lo, h)
        call constant_step(h, rk%constant_acceleration, ls%x, ls%x_lo, ls%v, ls%v_lo)
        stats%steps = stats%steps + 1
        if (iand(stats%steps, 4095_int64) == 0) then
          call checkpoint(sink, stats, ls%t, scene%t_end, error)
          if (allocated(error)) exit
        end if
        if (at_stop) then
          ls%t = t_stop
          ls%t_lo = 0.0_wp
          exit
        end if
      end do
      if (allocated(error)) exit
      call book_constant_ledger(scene, mode, x_start, x_lo_start, ls%x, ls%x_lo, ls%work, ls%work_lo, &
        ls%friction_loss, ls%friction_lo)
      if (.not. finite_state(ls%x, ls%v, ls%work)) then
        call raise_not_finite(ls%t, error)
        exit
      end if
      if (.not. (at_stop .and. quiet_sample(scene, stops, t_stop))) exit
      call emit_lanes(scene, ls, ke0, pe0, stops, sink, stats, error)
      if (allocated(error)) exit
      stops%sample_t = sample_time(scene, stops%j_sample)
    end do
  end subroutine glide

  !> n_bulk steps of dt under the mode's constant acceleration (constant_steps), in runs of
  !> up to the next progress report; renormalised once at the end. In lanes: the loop keeps
  !> the bodies in registers (3 ns a step; on the state's arrays the compiler spilled a
  !> running sum to memory and a step took 4.5 ns).
  subroutine bulk_steps(scene, rk, n_bulk, ls, sink, stats, error)
    type(scene_type), intent(in) :: scene
    type(rk4_type), intent(in) :: rk
    integer(int64), intent(in) :: n_bulk
    type(lane_state_type), intent(inout) :: ls
    class(sink_type), intent(inout) :: sink
    type(run_stats), intent(inout) :: stats
    type(error_type), allocatable, intent(inout) :: error
    real(wp) :: h, t, t_lo, x(max_lanes), x_lo(max_lanes), v(max_lanes), v_lo(max_lanes)
    real(wp) :: dv(max_lanes), half_dv(max_lanes)
    integer(int64) :: left, n
    h = scene%dt
    dv = h * rk%constant_acceleration
    half_dv = 0.5_wp * dv
    ! Plain local copies: the compiler keeps them in registers through the loop.
    t = ls%t
    t_lo = ls%t_lo
    x = ls%x
    x_lo = ls%x_lo
    v = ls%v
    v_lo = ls%v_lo
    left = n_bulk
    do while (left > 0)
      n = min(left, 4096_int64 - iand(stats%steps, 4095_int64))
      call rk%bulk_steps(n, h, dv, half_dv, t, t_lo, x, x_lo, v, v_lo)
      left = left - n
      stats%steps = stats%steps + n
      if (iand(stats%steps, 4095_int64) == 0) then
        call checkpoint(sink, stats, t, scene%t_end, error)
        if (allocated(error)) return       ! (an interrupt: the run ends, the state as it was)
      end if
    end do
    call renormalise(t, t_lo)
    call renormalise(x, x_lo)
    call renormalise(v, v_lo)
    ls%t = t
    ls%t_lo = t_lo
    ls%x = x
    ls%x_lo = x_lo
    ls%v = v
    ls%v_lo = v_lo
  end subroutine bulk_steps

  !> Sample j_sample of the run from a state in lanes (a glide's: no springs, so no potential
  !> energy); then the next one is due.
  subroutine emit_lanes(scene, ls, ke0, pe0, stops, sink, stats, error)
    type(scene_type), intent(in) :: scene
    type(lane_state_type), intent(in) :: ls
    real(wp), intent(in) :: ke0, pe0
    type(stops_type), intent(inout) :: stops
    class(sink_type), intent(inout) :: sink
    type(run_stats), intent(inout) :: stats
    type(error_type), allocatable, intent(out) :: error
    ! In lanes with the pair's masses (an idle lane: x2 = v2 = 0 and no kinetic energy, the
    ! columns a one-body scene's sinks leave out).
    call emit_sample(sink, stats, ls%t, ls%x, ls%v, scene%pair%mass, ke0, ls%work, ls%friction_loss, &
      ls%impact_loss, .false., [0.0_wp, pe0, 0.0_wp], error)
    stops%j_sample = stops%j_sample + 1
  end subroutine emit_lanes

  !> Quiet samples one step apart (dt_out = dt, as in the tutorial's scenes), each stop a
  !> single step from the last: with glide's per-stop set-up a step cost ~17 ns, here ~10
  !> (samples aside), so they take this loop. The step (constant_step), the ledger and the
  !> sample are glide's: the same bits. Scenes here have no springs (constant forces), so
  !> the sample has no potential energy. Returns at the first stop that is not such a sample.
  subroutine step_to_samples(scene, mode, rk, t_quiet, ke0, pe0, stops, ls, sink, stats, error)
    type(scene_type), intent(in) :: scene
    type(mode_type), intent(in) :: mode
    type(rk4_type), intent(in) :: rk
    real(wp), intent(in) :: t_quiet, ke0, pe0
    type(stops_type), intent(inout) :: stops
    type(lane_state_type), intent(inout) :: ls
    class(sink_type), intent(inout) :: sink
    type(run_stats), intent(inout) :: stats
    type(error_type), allocatable, intent(inout) :: error
    real(wp) :: t_stop, remaining, h, x_start(max_lanes), x_lo_start(max_lanes)
    logical :: books

    books = books_ledger(scene, mode)
    do
      t_stop = min(stops%sample_t, stops%t_break, stops%t_rest)
      if (.not. quiet_sample(scene, stops, t_stop)) exit
      remaining = (t_stop - ls%t) - ls%t_lo
      h = step_length(scene%dt, remaining)
      if (h /= remaining .or. h <= 0.0_wp .or. ls%t + h >= t_quiet) exit
      x_start = ls%x
      x_lo_start = ls%x_lo
      call constant_step(h, rk%constant_acceleration, ls%x, ls%x_lo, ls%v, ls%v_lo)
      ls%t = t_stop        ! (the step ends at the stop: the clock is set to it, as in glide)
      ls%t_lo = 0.0_wp
      stats%steps = stats%steps + 1
      if (iand(stats%steps, 4095_int64) == 0) then
        call checkpoint(sink, stats, ls%t, scene%t_end, error)
        if (allocated(error)) exit
      end if
      if (books) call book_constant_ledger(scene, mode, x_start, x_lo_start, ls%x, ls%x_lo, ls%work, ls%work_lo, &
        ls%friction_loss, ls%friction_lo)
      call emit_lanes(scene, ls, ke0, pe0, stops, sink, stats, error)
      if (allocated(error)) then
        ! The sample's row is checked whole (checking the state first cost ~15% of this
        ! loop); a state that is not finite is named as glide names it.
        if (.not. finite_state(ls%x, ls%v, ls%work)) call raise_not_finite(ls%t, error)
        exit
      end if
      stops%sample_t = sample_time(scene, stops%j_sample)
    end do
  end subroutine step_to_samples

  subroutine check_finite(s, error)
    type(lane_state_type), intent(in) :: s
    type(error_type), allocatable, intent(inout) :: error
    if (.not. finite_state(s%x, s%v, s%work)) call raise_not_finite(s%t, error)
  end subroutine check_finite

  subroutine raise_not_finite(t, error)
    real(wp), intent(in) :: t
    type(error_type), allocatable, intent(inout) :: error
    call raise(error, status_simulation, 'at t = ' // trim(fmt(t)) // ': the state is no longer finite')
  end subroutine raise_not_finite

  !> A gap that closed exactly at a stop (its root at the step's very end) with the bodies
  !> still approaching: the impact belongs to this instant, so the sample shows its result.
  !> (Between event points no entry scale applies.)
  pure logical function impact_due(scene, mode, s)
    type(scene_type), intent(in) :: scene
    type(mode_type), intent(in) :: mode
    type(lane_state_type), intent(in) :: s
    integer :: k
    real(wp), parameter :: no_scale(max_lanes) = 0.0_wp
    impact_due = .false.
    do k = 1, scene%n_rows
      if (mode%active(k)) cycle
      if (gap(scene, k, s) <= gap_tolerance(scene, k, s, 0.0_wp) .and. &
          normal_velocity(scene, k, s%v) < -u_tolerance(scene, mode, s, k, no_scale)) impact_due = .true.
    end do
  end function impact_due
end module impact1d_solver

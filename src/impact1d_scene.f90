!> The scene: what the user wrote (scene_input: named values, each given or not) and the
!> checked model the solver runs (scene_type). One validator serves the CLI and Python.
module impact1d_scene
  use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
  use, intrinsic :: iso_fortran_env, only: int64
  use impact1d_kinds, only: wp, eps_wp
  use impact1d_error, only: error_type, raise, status_input, fmt, fmt_width
  use impact1d_forcing, only: forcing_type, table_type, angular_frequency
  use impact1d_drives, only: drive_type
  use impact1d_fields, only: chain_input, mechanism_records, r_k, r_c, r_stop_k, r_stop_c, r_ground_v, &
    r_spring_ground_v, r_ground_table, r_spring_ground_table, array_value, a_m, &
    a_mu, a_mus, a_x, a_v, a_belt_v, a_v_s, a_c_v, a_belt_amp, a_belt_period, a_belt_phase, &
    a_f, a_f_amp, a_f_period, a_f_phase, a_f_table
  use impact1d_stability, only: linear_modes, stable_step, mode_error, coarse_rate, assemble
  implicit none
  private
  public :: n_real, n_text, real_names, text_names, scene_input, scene_type, build_scene, validate
  public :: i_left, i_right, i_slot_min, i_slot_max
  public :: i_m1, i_m2, i_mu1, i_mu2, i_g, i_x_left, i_r_left, i_x_right, i_r_right, i_d_min, &
    i_r_min, i_d_max, i_r_max, i_x1, i_v1, i_x2, i_v2, i_f1, i_f2, i_f1_amp, i_f1_period, &
    i_f1_phase, i_f2_amp, i_f2_period, i_f2_phase, i_t_end, i_dt, i_dt_out, i_mus1, i_mus2, &
    i_k1, i_x1_rest, i_c1, i_k2, i_x2_rest, i_c2, i_k12, i_d_rest, i_c12, i_max_events
  public :: sample_time, step_length, set_text, events_kept, name_of, is_nbody, value_or, ground_named
  public :: positive_value, nonnegative_value, unit_interval, resolvable, unresolved
  public :: i_x_left_v, i_x_right_v, i_x_left_table, i_x_right_table
  public :: i_title, i_f1_table, i_f2_table, i_method, i_substeps, i_events, default_gravity
  public :: events_all, events_impacts, events_none
  public :: name_len, set_rows, allocate_contacts, set_springs, springs_named, springs_type
  public :: tutorial_bodies

  !> The tutorial's bodies: a scene of at most this many is written with its scalars (m1,
  !> x2, k12, ...), and its output keeps their layout (the columns x2 v2, and events that
  !> report both bodies whatever the event). A format's number, not the engine's: the engine
  !> runs any N alike.
  integer, parameter :: tutorial_bodies = 2
  integer, parameter :: n_real = 52, n_text = 8
  !> Names of the real inputs, as in the namelist and in Python's Scene, in this order.
  character(len=*), parameter :: real_names(n_real) = [character(len=15) :: &
    'm1', 'm2', 'mu1', 'mu2', 'g', 'x_left', 'r_left', 'x_right', 'r_right', &
    'd_min', 'r_min', 'd_max', 'r_max', 'x1', 'v1', 'x2', 'v2', 'f1', 'f2', &
    'f1_amp', 'f1_period', 'f1_phase', 'f2_amp', 'f2_period', 'f2_phase', 't_end', 'dt', 'dt_out', &
    'zero_vel', 'max_rows', 'max_impulses', 'max_step_events', 'mus1', 'mus2', &
    'k1', 'x1_rest', 'c1', 'k2', 'x2_rest', 'c2', 'k12', 'd_rest', 'c12', 'max_events', &
    'x_left_v', 'x_left_amp', 'x_left_period', 'x_left_phase', 'x_right_v', 'x_right_amp', 'x_right_period', &
    'x_right_phase']
  character(len=*), parameter :: text_names(n_text) = [character(len=13) :: &
    'title', 'f1_table', 'f2_table', 'method', 'substeps', 'events', 'x_left_table', 'x_right_table']
  integer, parameter :: i_m1 = 1, i_m2 = 2, i_mu1 = 3, i_mu2 = 4, i_g = 5, i_x_left = 6, &
    i_r_left = 7, i_x_right = 8, i_r_right = 9, i_d_min = 10, i_r_min = 11, i_d_max = 12, &
    i_r_max = 13, i_x1 = 14, i_v1 = 15, i_x2 = 16, i_v2 = 17, i_f1 = 18, i_f2 = 19, &
    i_f1_amp = 20, i_f1_period = 21, i_f1_phase = 22, i_f2_amp = 23, i_f2_period = 24, &
    i_f2_phase = 25, i_t_end = 26, i_dt = 27, i_dt_out = 28, i_zero_vel = 29, &
    i_max_rows = 30, i_max_impulses = 31, i_max_step_events = 32, i_mus1 = 33, i_mus2 = 34, &
    i_k1 = 35, i_x1_rest = 36, i_c1 = 37, i_k2 = 38, i_x2_rest = 39, i_c2 = 40, i_k12 = 41, &
    i_d_rest = 42, i_c12 = 43, i_max_events = 44
  !> The walls' prescribed motion (impact1d_chain's wall_records): v, amp, period, phase each.
  integer, parameter :: i_x_left_v = 45, i_x_right_v = 49
  !> What only a second body can have: refused in a one-body scene (no m2).
  integer, parameter :: body2_fields(18) = [i_x2, i_v2, i_mu2, i_mus2, i_f2, i_f2_amp, i_f2_period, &
    i_f2_phase, i_k2, i_x2_rest, i_c2, i_k12, i_d_rest, i_c12, i_d_min, i_r_min, i_d_max, i_r_max]
  !> The tutorial's spring elements (body 1 to the ground, body 2 to the ground, between the
  !> bodies: impact1d_chain's input_records makes their records, in this order); each one's
  !> stiffness (its rest position and damping follow it).
  integer, parameter :: n_tutorial_elements = 3
  integer, parameter :: spring_index(n_tutorial_elements) = [i_k1, i_k2, i_k12]
  integer, parameter :: i_title = 1, i_f1_table = 2, i_f2_table = 3, i_method = 4, i_substeps = 5, &
    i_events = 6
  !> The walls' tables (x_left_table, x_right_table: a wall's ground_table, wall_records).
  integer, parameter :: i_x_left_table = 7, i_x_right_table = 8
  !> What the event log keeps (&run events): every event, the impacts only, nothing. The
  !> run's counts (the summary, a sweep's row) are exact whatever it keeps.
  integer, parameter :: events_all = 0, events_impacts = 1, events_none = 2

  !> The tutorial's four optional limits (left, right, slot_min, slot_max: the rows of its
  !> scenes in this order, which validate checks; input_records makes their records).
  integer, parameter :: n_limits = 4, i_left = 1, i_right = 2, i_slot_min = 3, i_slot_max = 4
  character(len=*), parameter :: contact_names(n_limits) = [character(len=8) :: &
    'left', 'right', 'slot_min', 'slot_max']
  !> Their normals with two bodies: the left wall holds body 1, the right wall body 2. With
  !> one body both walls hold body 1.
  real(wp), parameter :: two_body_normal(2, n_limits) = reshape( &
    [1.0_wp, 0.0_wp, 0.0_wp, -1.0_wp, -1.0_wp, 1.0_wp, 1.0_wp, -1.0_wp], [2, n_limits])
  real(wp), parameter :: one_body_normal(2, n_limits) = reshape( &
    [1.0_wp, 0.0_wp, -1.0_wp, 0.0_wp, -1.0_wp, 1.0_wp, 1.0_wp, -1.0_wp], [2, n_limits])

  !> Longest name of a contact record or row ('slot_max', a user's '<name>_min').
  integer, parameter :: name_len = 32

  real(wp), parameter :: default_gravity = 9.80665_wp
  !> Bodies up to which build_scene checks dt against the springs' modes (a dense eigenproblem).
  integer, parameter :: max_modal_bodies = 400
  !> The tutorial's zero-velocity threshold, used by the vissim method only.
  real(wp), parameter :: default_zero_velocity = 0.005_wp
  !> Output rows a run may produce: beyond this the user almost surely meant a larger dt_out.
  !> Work limits, each a &run option (max_rows, max_impulses, max_step_events): output rows
  !> of one run; impulses at one instant (elastic chains need ~pi sqrt(M/m)); event points
  !> within one step's length of simulated time (a run that no longer advances).
  integer, parameter :: max_samples = 10000000
  integer, parameter :: default_max_impulses = 1000000, default_max_step_events = 100000
  !> Events the log keeps (&run max_events): past it the run goes on and the log ends with a
  !> note (the counts stay exact). 10^7 lines are about 1.4 GB: a runaway log stops well
  !> before a disk or memory fills, a long study's (1.48 M events in 1e5 s) fits whole.
  integer, parameter :: default_max_events = 10000000
  !> A positive gap or limit below this many units of rounding (eps) of its coordinates is
  !> refused: the solver's start-contact tolerance is 16 of them, so 64 leaves a clear margin.
  real(wp), parameter :: min_resolved_ulps = 64.0_wp
  !> The smallest step, in units of the clock's spacing at t_end.
  real(wp), parameter :: clock_resolution_ulps = 8.0_wp

  !> One text of a scene (title, table path, method), kept whole whatever its length. (Not
  !> an array of deferred-length strings: gfortran 12 copies such a component wrongly when
  !> a scene_input is assigned, the texts after the first coming out blank.)
  type :: scene_text
    character(len=:), allocatable :: s
  end type scene_text

  !> A scene as written: values and texts, each given or absent (an empty text is absent).
  !> Every maker of a scene_input sets all its texts (set_text), '' when absent.
  type :: scene_input
    real(wp) :: value(n_real) = 0.0_wp
    logical :: given(n_real) = .false.
    type(scene_text) :: text(n_text)
    character(len=:), allocatable :: source
    !> The name written for value i when it is not real_names(i): 'm(2)' from 'm = 1.0, 2.0'.
    character(len=16) :: spelled(n_real) = ''
    !> Arrays of more than two bodies and &contact / &spring records (impact1d_fields).
    type(chain_input) :: chain
    !> The bodies whose x and v the output has (&run bodies_out, --bodies-out; impact1d_output's
    !> present_columns): not allocated, every body.
    integer, allocatable :: bodies_out(:)
  end type scene_input

  !> What the scene's elements and compliant stops make of its forces (set_springs,
  !> springs_named); the engine reads the element records themselves (impact1d_elements).
  type :: springs_type
    !> Forces that depend on the state: an element record or a compliant stop.
    logical :: present = .false.
    !> The scene names a stiffness / a damping (its output has the PE / damping_loss column).
    logical :: has_spring = .false., has_damper = .false.
  end type springs_type

  !> The checked model: the constant part of a run (what changes is impact1d_state's), as
  !> counts and one array per attribute (MuJoCo's mjModel).
  type :: scene_type
    character(len=:), allocatable :: title, method
    !> What the run should know but does not stop it (a coarse step), one per line; '' if none.
    character(len=:), allocatable :: warnings
    !> RK4 steps per dt (&run substeps = 'auto' with springs or dampers coarse for dt: the
    !> step taken is dt / substeps); 1 otherwise.
    integer :: substeps = 1
    !> What the event log keeps: events_all, events_impacts or events_none (&run events).
    integer :: events = events_all
    ! bodies ------------------------------------------------------------------------------
    integer :: n_bodies = 2                          !< N: 1 (m2 not given) or 2
    real(wp), allocatable :: body_mass(:)            !< (N) kg
    real(wp), allocatable :: body_friction(:)        !< (N) sliding friction bound c_i = (mu_i m_i) g, N
    real(wp), allocatable :: body_static(:)          !< (N) static friction bound (mus_i m_i) g >= c_i, N
    real(wp), allocatable :: body_x0(:), body_v0(:)  !< (N) initial position (m) and velocity (m/s)
    type(forcing_type) :: forcing                    !< the external forces f_i(t), per body (N)
    ! friction laws (impact1d_friction_laws; docs/method.md section 12), allocated only in
    ! a scene that names them: a friction surface moving under each body (belt_v), Stribeck's
    ! sliding friction (v_s, c_v). Only the N-body engine runs them.
    logical :: belts = .false.                       !< some body names belt_v
    logical :: stribeck = .false.                    !< some body names v_s or c_v
    real(wp), allocatable :: body_belt(:)            !< (N) its friction surface's velocity, m/s
    !> some body's belt has a sine speed (belt_amp /= 0): V_i(t) = body_belt_i + belt_amp_i
    !> sin(belt_omega_i t + belt_phase_i), the three arrays allocated only then
    logical :: belt_moves = .false.
    real(wp), allocatable :: body_belt_amp(:), body_belt_omega(:), body_belt_phase(:)   !< (N) m/s, rad/s, rad
    !> add_belt_sine, called through a pointer (impact1d_friction_laws' belt_speed): inlined,
    !> its sine made the slip of every friction scene too big to inline where it was
    !> (callgrind, the CLI's run: input/drill_string.nml +0.8%, stick_slip.nml on the N-body
    !> engine +0.7%, neither with a belt of sine speed)
    procedure(add_belt_sine), pointer, nopass :: belt_sine => add_belt_sine
    !> a body may be held to a moving ground or stuck on an accelerating belt (drives or
    !> belt_moves): the RK4 step moves it with that motion (impact1d_nbody_step's
    !> hold_to_drives, one test for both)
    logical :: held_motion = .false.
    real(wp), allocatable :: body_v_s(:)             !< (N) Stribeck velocity, m/s (0: none)
    real(wp), allocatable :: body_viscous(:)         !< (N) viscous friction c_v m g, N s/m
    ! friction contacts between two bodies (&friction records; docs/method.md section 13),
    ! on the relative velocity v_b - v_a; allocated only in a scene that has one. Only the
    ! N-body engine runs them.
    integer :: n_frictions = 0
    integer, allocatable :: friction_body(:, :)      !< (2, nf) ends a, b (bodies)
    real(wp), allocatable :: friction_slide(:)       !< (nf) sliding bound mu normal, N
    real(wp), allocatable :: friction_static(:)      !< (nf) static bound mus normal >= friction_slide, N
    character(len=name_len), allocatable :: friction_name(:)   !< (nf) events stick_<name>, slip_<name>
    !> The N-body engine's RK4 stages book powers (moving grounds, a friction law or compliant
    !> stops: its nbody_step's moving_stage), set by build_scene: one test in the stage's hot
    !> path (a second test there and gfortran no longer inlines the stage).
    logical :: stage_powers = .false.
    ! elements: springs and dampers, each pulling its ends together with tension
    ! k ((x_b - x_a) - rest) + c (v_b - v_a) (a ground end at x = 0)
    integer :: n_elements = 0
    integer, allocatable :: element_body(:, :)       !< (2, ne) ends a, b; 0 = ground
    real(wp), allocatable :: element_k(:)            !< (ne) stiffness, N/m
    real(wp), allocatable :: element_c(:)            !< (ne) damping, N s/m
    real(wp), allocatable :: element_rest(:)         !< (ne) rest length of x_b - x_a, m
    real(wp), allocatable :: element_ratio(:)        !< (ne) gear ratio n: acts on x_b - n x_a (1: none)
    !> Whether the elements or stops make the forces depend on the state, and whether the
    !> scene names a stiffness or a damping (present, has_spring, has_damper).
    type(springs_type) :: springs
    ! contacts: the records as written (docs/nbody-plan.md section 1). Record j constrains
    ! d = x_b - x_a (a ground end is 0: x = 0) between its limits, d_min <= d <= d_max.
    integer :: n_contacts = 0
    integer, allocatable :: contact_body(:, :)          !< (2, nc) ends a, b; 0 = ground; acts on x_b - x_a
    logical, allocatable :: contact_has(:, :)           !< (2, nc) lower / upper limit present
    real(wp), allocatable :: contact_limit(:, :)        !< (2, nc) d_min, d_max on x_b - x_a (walls: positions)
    real(wp), allocatable :: contact_restitution(:, :)  !< (2, nc) Newton's r at the lower, upper limit
    character(len=name_len), allocatable :: contact_name(:)  !< (nc) 'left', 'right', 'slot', ...
    !> (nc) a compliant stop's stiffness (N/m) and damping (N s/m); k = 0: a rigid contact
    real(wp), allocatable :: contact_k(:), contact_c(:)
    !> (nc) gear ratio n: the record acts on x_b - n x_a (1: none; docs/method.md section 14)
    real(wp), allocatable :: contact_ratio(:)
    !> Some contact or element has a gear ratio other than 1: the event method runs it, its
    !> RK4 stages through the elements' geared forces (stage_powers), its
    !> modes and impacts on rows of normal (-n, 1) (body_mode_type's scale).
    logical :: geared = .false.
    !> Moving grounds or gear ratios (drives%n > 0 or geared): one test where a gap, a mode's
    !> accelerations or the elements' forces have terms beyond a still ground's unit rows,
    !> so that a scene with neither pays one test there, as before either was built.
    logical :: gap_terms = .false.
    ! rows: one unilateral constraint per present limit, what the engine loops over, made
    ! from the records by set_rows in record order, lower limit first (docs/nbody-plan.md
    ! B4: left, right, slot_min, slot_max); gap_r = row_normal(:, r) . x(row_body(:, r))
    ! + row_offset(r) >= 0.
    ! The rigid rows come first (1..n_rows: what the impacts, the modes and the location of
    ! closing gaps loop over), then the compliant stops' rows (n_rows + 1 .. n_rows +
    ! n_stops: a force k p + c p' while engaged, docs/method.md section 10); nr is their sum.
    integer :: n_rows = 0
    integer :: n_stops = 0                              !< rows of compliant stops (after the rigid ones)
    real(wp), allocatable :: row_k(:), row_c(:)         !< (nr) a stop row's stiffness and damping (0: rigid)
    integer, allocatable :: row_contact(:)              !< (nr) the record it comes from
    integer, allocatable :: row_body(:, :)              !< (2, nr) ends a, b (a = 0: ground)
    real(wp), allocatable :: row_normal(:, :)           !< (2, nr) on x_a, x_b: lower (-1, 1), upper (1, -1);
                                                        !< 0 on a ground end
    real(wp), allocatable :: row_offset(:)              !< (nr) -d_min (lower) or +d_max (upper)
    real(wp), allocatable :: row_restitution(:)         !< (nr) Newton's restitution
    integer, allocatable :: row_partner(:)              !< (nr) the other limit of a rigid link (d_min = d_max), else 0
    character(len=name_len), allocatable :: row_name(:) !< (nr) one limit: the record's name; two (and
                                                        !< always the link 'slot'): <name>_min, <name>_max
    ! Prescribed motion of ground ends (impact1d_drives): the ground end of a record that
    ! names it is at w_d(t) (d its drive, 0: the ground at x = 0). Only the N-body engine
    ! runs them (impact1d_solver's run hands it every scene with a drive).
    type(drive_type) :: drives
    integer, allocatable :: contact_drive(:)            !< (nc) the drive of the record's ground end, else 0
    integer, allocatable :: element_drive(:)            !< (ne) the drive of the element's ground end, else 0
    integer, allocatable :: row_drive(:)                !< (nr) its record's drive
    ! run --------------------------------------------------------------------------------
    real(wp) :: t_end, dt, dt_out
    real(wp) :: zero_velocity = default_zero_velocity
    integer :: max_impulses = default_max_impulses, max_step_events = default_max_step_events
    integer :: max_events = default_max_events
    integer :: n_samples
  end type scene_type

contains

  !> Check what the user wrote. With require_run false the &run values may still come from
  !> overrides (the CLI's options, Python's keywords), so their absence is not yet an error.
  subroutine validate(input, require_run, error)
    type(scene_input), intent(in) :: input
    logical, intent(in) :: require_run
    type(error_type), allocatable, intent(out) :: error
    integer :: k

    do k = 1, n_text
      if (.not. allocated(input%text(k)%s)) then
        call raise(error, status_input, 'internal: ' // trim(text_names(k)) // ' was never set (set_text)')
        return
      end if
    end do
    do k = 1, n_real
      if (input%given(k) .and. .not. ieee_is_finite(input%value(k))) then
        call raise(error, status_input, trim(name_of(input, k)) // ' = ' // trim(fmt(input%value(k))) // &
          ' is not a finite number')
        return
      end if
    end do
    if (input%chain%n_bodies > tutorial_bodies) then
      ! The bodies and links are impact1d_chain's to check (validate_chain), as are the
      ! records of any scene.
      if (require_run) call require(input, [i_t_end, i_dt], error)
      call nonnegative(input, i_zero_vel, error)
      call run_limits(input, error)
      call restitution(input, i_r_left, i_x_left, error); call restitution(input, i_r_right, i_x_right, error)
      call walls_ordered(input, error)
    else
      call validate_bodies(input, require_run, error)
    end if
    if (allocated(error)) return
    call validate_run(input, error)
  end subroutine validate

  !> The checks of a one- or two-body scene written with the tutorial's names.
  subroutine validate_bodies(input, require_run, error)
    type(scene_input), intent(in) :: input
    logical, intent(in) :: require_run
    type(error_type), allocatable, intent(inout) :: error
    integer :: k
    real(wp) :: gap, scale, nrm(2, n_limits)

    ! Without m2 the scene has one body, and nothing may name the second.
    call require(input, [i_m1, i_x1], error)
    if (allocated(error)) return
    if (input%given(i_m2)) then
      call require(input, [i_x2], error)
    else
      do k = 1, size(body2_fields)
        if (input%given(body2_fields(k))) then
          call raise(error, status_input, trim(name_of(input, body2_fields(k))) // ' is given but m2 is not: ' // &
            'a scene without m2 has one body (give m2 for a second one)')
          return
        end if
      end do
      if (len_trim(input%text(i_f2_table)%s) > 0) then
        call raise(error, status_input, 'f2_table is given but m2 is not: a scene without m2 has one body ' // &
          '(give m2 for a second one)')
        return
      end if
    end if
    if (allocated(error)) return
    if (require_run) call require(input, [i_t_end, i_dt], error)
    if (allocated(error)) return

    call positive(input, i_m1, error)
    if (input%given(i_m2)) call positive(input, i_m2, error)
    if (allocated(error)) return
    call nonnegative(input, i_mu1, error)
    call nonnegative(input, i_mu2, error)
    call nonnegative(input, i_zero_vel, error)
    call nonnegative(input, i_mus1, error); call nonnegative(input, i_mus2, error)
    do k = 1, n_tutorial_elements
      call nonnegative(input, spring_index(k), error); call nonnegative(input, spring_index(k) + 2, error)
    end do
    if (allocated(error)) return
    do k = 0, 1
      if (input%given(i_mus1 + k) .and. input%value(i_mus1 + k) < value_or(input, i_mu1 + k, 0.0_wp)) then
        call raise(error, status_input, trim(name_of(input, i_mus1 + k)) // ' = ' // &
          trim(fmt(input%value(i_mus1 + k))) // &
          ' is below ' // trim(name_of(input, i_mu1 + k)) // ' = ' // trim(fmt(value_or(input, i_mu1 + k, 0.0_wp))) // &
          ': static friction is at least the sliding friction')
        return
      end if
    end do
    ! A spring needs the position at which it is relaxed; a rest position needs its spring.
    do k = 1, n_tutorial_elements
      if (input%given(spring_index(k)) .neqv. input%given(spring_index(k) + 1)) then
        if (input%given(spring_index(k))) then
          call raise(error, status_input, trim(name_of(input, spring_index(k))) // ' is given but ' // &
            trim(name_of(input, spring_index(k) + 1)) // ' is not: a spring needs its rest position')
        else
          call raise(error, status_input, trim(name_of(input, spring_index(k) + 1)) // ' is given but ' // &
            trim(name_of(input, spring_index(k))) // ' is not: a rest position needs its spring')
        end if
        return
      end if
    end do
    call run_limits(input, error)
    if (allocated(error)) return
    if (input%given(i_g) .and. input%value(i_g) < 0.0_wp .and. (value_or(input, i_mu1, 0.0_wp) > 0.0_wp &
        .or. value_or(input, i_mu2, 0.0_wp) > 0.0_wp .or. value_or(input, i_mus1, 0.0_wp) > 0.0_wp .or. &
        value_or(input, i_mus2, 0.0_wp) > 0.0_wp)) then
      call raise(error, status_input, 'g = ' // trim(fmt(input%value(i_g))) // &
        ' is negative with friction: the normal force m g must not pull the bodies off the surface')
      return
    end if
    call restitution(input, i_r_left, i_x_left, error); call restitution(input, i_r_right, i_x_right, error)
    call restitution(input, i_r_min, i_d_min, error); call restitution(input, i_r_max, i_d_max, error)
    call walls_ordered(input, error)
    if (allocated(error)) return
    if (input%given(i_d_max) .and. .not. input%given(i_d_min) .and. input%value(i_d_max) < 0.0_wp) then
      call raise(error, status_input, 'd_max = ' // trim(fmt(input%value(i_d_max))) // ' is negative, but ' // &
        'without d_min the bodies meet at x2 = x1 (d_min = 0): give d_min to let them pass')
      return
    end if
    if (input%given(i_d_min) .and. input%given(i_d_max)) then
      if (input%value(i_d_min) > input%value(i_d_max)) then
        call raise(error, status_input, 'd_min = ' // trim(fmt(input%value(i_d_min))) // &
          ' must not exceed d_max = ' // trim(fmt(input%value(i_d_max))))
        return
      end if
    end if
    call sine_terms(input, i_f1_amp, i_f1_period, i_f1_phase, error)
    call sine_terms(input, i_f2_amp, i_f2_period, i_f2_phase, error)
    if (allocated(error)) return

    ! The initial state must satisfy every constraint; a gap within the rounding of the
    ! numbers it is made of (this contact's positions and limit) is contact. A gap or limit
    ! that is positive but within a few dozen ulps of the coordinates it is measured
    ! against cannot be told from contact (case 3 moved to x = 2e14 m got an impact across
    ! its 0.5 m gap): refused, as is a friction bound mu m g that overflows.
    do k = 1, n_limits
      if (.not. has_limit(input, k)) cycle
      nrm = contact_normals(input)
      gap = nrm(1, k) * input%value(i_x1) + nrm(2, k) * input%value(i_x2) + offset_of(input, k)
      if (k <= i_right) gap = gap + offset_sign(k) * wall_start(input, k)
      scale = maxval(abs(nrm(:, k) * input%value([i_x1, i_x2])))
      if (gap < -16.0_wp * eps_wp * max(scale, abs(offset_of(input, k)))) then
        if (input%given(limit_index(k))) then
          call raise(error, status_input, 'the initial state ' // trim(initial_positions(input)) // &
            ' violates the ' // &
            trim(contact_names(k)) // ' constraint (' // trim(name_of(input, limit_index(k))) // ' = ' // &
            trim(fmt(limit_value(input, k))) // ')')
        else
          call raise(error, status_input, 'the initial state ' // trim(initial_positions(input)) // &
            ' violates the ' // &
            trim(contact_names(k)) // ' constraint (d_min = 0 by default: the bodies meet at x2 = x1)')
        end if
        return
      end if
      ! Within the rounding of the user's decimals (the contact test below) it is contact.
      if (gap > 16.0_wp * eps_wp * max(scale, abs(offset_of(input, k)))) &
        call resolvable('the initial ' // trim(contact_names(k)) // ' gap', gap, &
          max(scale, abs(offset_of(input, k))), error)
      if (allocated(error)) return
    end do
    scale = maxval(abs(input%value([i_x1, i_x2])))
    if (input%given(i_x_left)) scale = max(scale, abs(input%value(i_x_left)))
    if (input%given(i_x_right)) scale = max(scale, abs(input%value(i_x_right)))
    if (input%given(i_x_left) .and. input%given(i_x_right)) &
      call resolvable('the walls'' distance x_right - x_left', &
        input%value(i_x_right) - input%value(i_x_left), scale, error)
    if (input%given(i_d_min)) call resolvable('d_min', input%value(i_d_min), scale, error)
    if (input%given(i_d_max)) call resolvable('d_max', input%value(i_d_max), scale, error)
    if (input%given(i_d_min) .and. input%given(i_d_max)) &
      call resolvable('the slot''s width d_max - d_min', &
        input%value(i_d_max) - input%value(i_d_min), scale, error)
    if (allocated(error)) return
    do k = 0, 3
      associate (i => merge(i_mu1, i_mus1, k < 2) + mod(k, 2))
        if (.not. input%given(i)) cycle
        if (input%value(i) * input%value(i_m1 + mod(k, 2)) * abs(value_or(input, i_g, default_gravity)) > &
            huge(1.0_wp)) then
          call raise(error, status_input, trim(name_of(input, i)) // ' = ' // trim(fmt(input%value(i))) // &
            ': the friction bound mu m g overflows')
          return
        end if
      end associate
    end do
  end subroutine validate_bodies

  !> The checks of &run (and of overrides of its values).
  subroutine validate_run(input, error)
    type(scene_input), intent(in) :: input
    type(error_type), allocatable, intent(inout) :: error
    real(wp) :: rows, limit

    if (input%given(i_t_end)) then
      if (input%value(i_t_end) <= 0.0_wp) then
        call raise(error, status_input, 't_end = ' // trim(fmt(input%value(i_t_end))) // ' must be positive')
        return
      end if
    end if
    if (input%given(i_dt)) then
      if (input%value(i_dt) <= 0.0_wp) then
        call raise(error, status_input, 'dt = ' // trim(fmt(input%value(i_dt))) // ' must be positive')
        return
      end if
    end if
    ! A step the clock cannot resolve near t_end never advances the run (dt = 1e-320 ran for
    ! minutes): at least 8 ulps of t_end, so that t + dt moves the clock by dt to 1 part in 8.
    if (input%given(i_dt) .and. input%given(i_t_end)) then
      if (input%value(i_dt) < clock_resolution_ulps * spacing(abs(input%value(i_t_end)))) then
        call raise(error, status_input, 'dt = ' // trim(fmt(input%value(i_dt))) // ' is below the clock''s ' // &
          'resolution at t_end = ' // trim(fmt(input%value(i_t_end))) // ' (' // &
          trim(fmt(clock_resolution_ulps * spacing(abs(input%value(i_t_end))))) // ' s): the run could not advance')
        return
      end if
    end if
    ! dt_out < dt is fine: the run stops at every sample time whatever its step.
    if (input%given(i_dt_out)) then
      if (input%value(i_dt_out) <= 0.0_wp) then
        call raise(error, status_input, 'dt_out = ' // trim(fmt(input%value(i_dt_out))) // ' must be positive')
        return
      end if
    end if
    if (input%given(i_t_end) .and. (input%given(i_dt) .or. input%given(i_dt_out))) then
      rows = row_count(input%value(i_t_end), value_or(input, i_dt_out, input%value(i_dt)))
      limit = value_or(input, i_max_rows, real(max_samples, wp))
      if (rows > limit) then
        call raise(error, status_input, 't_end / dt_out = ' // &
          trim(fmt(input%value(i_t_end) / value_or(input, i_dt_out, input%value(i_dt)))) // &
          ' makes ' // trim(fmt_count(rows)) // ' output rows (t = 0 included), over the limit of ' // &
          trim(fmt_count(limit)) // ': set a larger dt_out (or &run max_rows)')
        return
      end if
    end if
    call keyword(input, i_substeps, ['none', 'auto'], error)
    call keyword(input, i_events, ['all    ', 'impacts', 'none   '], error)
    if (allocated(error)) return
    if (len_trim(input%text(i_method)%s) > 0) then
      if (trim(input%text(i_method)%s) /= 'event' .and. trim(input%text(i_method)%s) /= 'vissim') then
        call raise(error, status_input, "method = '" // trim(input%text(i_method)%s) // &
          "' is unknown: the methods are 'event' and 'vissim'")
        return
      end if
    end if
  end subroutine validate_run

  !> The work limits of &run, each when given.
  subroutine run_limits(input, error)
    type(scene_input), intent(in) :: input
    type(error_type), allocatable, intent(inout) :: error
    call count_limit(input, i_max_rows, error)
    call count_limit(input, i_max_impulses, error)
    call count_limit(input, i_max_step_events, error)
    call count_limit(input, i_max_events, error)
  end subroutine run_limits

  !> The left wall is left of the right one.
  subroutine walls_ordered(input, error)
    type(scene_input), intent(in) :: input
    type(error_type), allocatable, intent(inout) :: error
    if (allocated(error) .or. .not. (input%given(i_x_left) .and. input%given(i_x_right))) return
    if (input%value(i_x_left) >= input%value(i_x_right)) call raise(error, status_input, 'x_left = ' // &
      trim(fmt(input%value(i_x_left))) // ' must be less than x_right = ' // trim(fmt(input%value(i_x_right))))
  end subroutine walls_ordered

  !> The name the user wrote for value i: the tutorial's ('m2'), or the array element a
  !> chain written for one or two bodies put there ('m(2)').
  pure function name_of(input, i) result(name)
    type(scene_input), intent(in) :: input
    integer, intent(in) :: i
    character(len=16) :: name     ! blank padded: callers trim
    name = real_names(i)
    if (len_trim(input%spelled(i)) > 0) name = input%spelled(i)
  end function name_of

  !> Whether the scene is written as arrays of more than two bodies (else with the
  !> tutorial's scalars, one or two bodies: read, checked and built from those).
  pure logical function is_nbody(input)
    type(scene_input), intent(in) :: input
    is_nbody = input%chain%n_bodies > tutorial_bodies
  end function is_nbody

  !> What the event log of a run of this input keeps (&run events; all by default).
  pure integer function events_kept(input)
    type(scene_input), intent(in) :: input
    events_kept = events_all
    if (input%text(i_events)%s == 'impacts') events_kept = events_impacts
    if (input%text(i_events)%s == 'none') events_kept = events_none
  end function events_kept

  !> Text field i, when given, is one of the words allowed.
  subroutine keyword(input, i, allowed, error)
    type(scene_input), intent(in) :: input
    integer, intent(in) :: i
    character(len=*), intent(in) :: allowed(:)
    type(error_type), allocatable, intent(inout) :: error
    character(len=:), allocatable :: listed
    integer :: j
    if (allocated(error) .or. len_trim(input%text(i)%s) == 0) return
    if (any(trim(input%text(i)%s) == allowed)) return
    listed = ''
    do j = 1, size(allowed)
      listed = listed // merge(', ', '  ', j > 1) // "'" // trim(allowed(j)) // "'"
    end do
    call raise(error, status_input, trim(text_names(i)) // " = '" // trim(input%text(i)%s) // &
      "' is unknown: it is one of " // trim(adjustl(listed)))
  end subroutine keyword

  !> Each of indices is given (the first that is not is the error).
  subroutine require(input, indices, error)
    type(scene_input), intent(in) :: input
    type(error_type), allocatable, intent(inout) :: error
    integer, intent(in) :: indices(:)
    integer :: j
    do j = 1, size(indices)
      if (.not. input%given(indices(j))) then
        call raise(error, status_input, trim(name_of(input, indices(j))) // ' is required but not given')
        return
      end if
    end do
  end subroutine require

  !> Value i is above zero (unless an earlier check failed).
  subroutine positive(input, i, error)
    type(scene_input), intent(in) :: input
    type(error_type), allocatable, intent(inout) :: error
    integer, intent(in) :: i
    ! (the name's text only for a value that fails: a set-up builds no strings)
    if (input%value(i) <= 0.0_wp) call positive_value(trim(name_of(input, i)), input%value(i), error)
  end subroutine positive

  !> 'name = value must be positive' unless value > 0 (or an earlier check failed).
  subroutine positive_value(name, value, error)
    character(len=*), intent(in) :: name
    real(wp), intent(in) :: value
    type(error_type), allocatable, intent(inout) :: error
    if (allocated(error)) return
    if (value <= 0.0_wp) call raise(error, status_input, name // ' = ' // trim(fmt(value)) // ' must be positive')
  end subroutine positive_value

  !> A work limit: a whole number from 1 to the largest default integer.
  subroutine count_limit(input, i, error)
    type(scene_input), intent(in) :: input
    type(error_type), allocatable, intent(inout) :: error
    integer, intent(in) :: i
    if (allocated(error) .or. .not. input%given(i)) return
    if (input%value(i) < 1.0_wp .or. input%value(i) > real(huge(1), wp) .or. &
        input%value(i) /= aint(input%value(i))) call raise(error, status_input, trim(name_of(input, i)) // &
      ' = ' // trim(fmt(input%value(i))) // ' must be a whole number from 1 to ' // trim(fmt(huge(1))))
  end subroutine count_limit

  !> Value i, when given, is not below zero.
  subroutine nonnegative(input, i, error)
    type(scene_input), intent(in) :: input
    type(error_type), allocatable, intent(inout) :: error
    integer, intent(in) :: i
    if (input%given(i)) then
      if (input%value(i) < 0.0_wp) call nonnegative_value(trim(name_of(input, i)), input%value(i), error)
    end if
  end subroutine nonnegative

  !> 'name = value must not be negative' unless value >= 0 (or an earlier check failed).
  subroutine nonnegative_value(name, value, error)
    character(len=*), intent(in) :: name
    real(wp), intent(in) :: value
    type(error_type), allocatable, intent(inout) :: error
    if (allocated(error)) return
    if (value < 0.0_wp) call raise(error, status_input, name // ' = ' // trim(fmt(value)) // ' must not be negative')
  end subroutine nonnegative_value

  !> A restitution 'name = value' is in [0, 1] (unless an earlier check failed).
  subroutine unit_interval(name, value, error)
    character(len=*), intent(in) :: name
    real(wp), intent(in) :: value
    type(error_type), allocatable, intent(inout) :: error
    if (allocated(error)) return
    if (value < 0.0_wp .or. value > 1.0_wp) call raise(error, status_input, name // ' = ' // &
      trim(fmt(value)) // ' is outside [0, 1]')
  end subroutine unit_interval

  !> Restitution i, when given, is in [0, 1] and has its constraint (owner).
  subroutine restitution(input, i, owner, error)
    type(scene_input), intent(in) :: input
    type(error_type), allocatable, intent(inout) :: error
    integer, intent(in) :: i, owner
    if (allocated(error) .or. .not. input%given(i)) return
    if (input%value(i) < 0.0_wp .or. input%value(i) > 1.0_wp) then
      call unit_interval(trim(name_of(input, i)), input%value(i), error)
      return
    end if
    if (.not. input%given(owner) .and. i /= i_r_min) then
      ! (r_min alone is the restitution of the bodies meeting: d_min = 0 by default.)
      call raise(error, status_input, trim(name_of(input, i)) // ' is given but ' // &
        trim(name_of(input, owner)) // ' is not: a restitution needs its constraint')
    end if
  end subroutine restitution

  !> A sine force's amplitude and period go together; its phase needs them.
  subroutine sine_terms(input, i_amp, i_period, i_phase, error)
    type(scene_input), intent(in) :: input
    type(error_type), allocatable, intent(inout) :: error
    integer, intent(in) :: i_amp, i_period, i_phase
    if (allocated(error)) return
    if (input%given(i_amp) .neqv. input%given(i_period)) then
      call raise(error, status_input, trim(name_of(input, i_amp)) // ' and ' // trim(name_of(input, i_period)) // &
        ' go together: a sine force needs both')
    else if (input%given(i_phase) .and. .not. input%given(i_amp)) then
      call raise(error, status_input, trim(name_of(input, i_phase)) // ' is given but ' // &
        trim(name_of(input, i_amp)) // ' is not')
    else if (input%given(i_period)) then
      if (input%value(i_period) <= 0.0_wp) call raise(error, status_input, trim(name_of(input, i_period)) // &
        ' = ' // trim(fmt(input%value(i_period))) // ' must be positive')
    end if
  end subroutine sine_terms

  !> A positive length below min_resolved_ulps units of rounding of scale: resolvable's
  !> test, for callers that make its message only when it fails.
  pure logical function unresolved(length, scale)
    real(wp), intent(in) :: length, scale
    unresolved = length > 0.0_wp .and. length < min_resolved_ulps * eps_wp * scale
  end function unresolved

  !> A length the scene relies on: zero (contact, a rigid link), or at least
  !> min_resolved_ulps units of rounding of the coordinates it is measured against.
  subroutine resolvable(what, length, scale, error)
    type(error_type), allocatable, intent(inout) :: error
    character(len=*), intent(in) :: what
    real(wp), intent(in) :: length, scale
    if (allocated(error)) return
    if (.not. unresolved(length, scale)) return
    call raise(error, status_input, what // ' = ' // trim(fmt(length)) // ' is below the resolution of ' // &
      'the scene''s coordinates (|x| up to ' // trim(fmt(scale)) // ' m resolves ' // &
      trim(fmt(min_resolved_ulps * eps_wp * scale)) // ' m): move the scene nearer the origin')
  end subroutine resolvable

  !> 'x1 = .., x2 = ..' (x1 alone in a one-body scene), for messages.
  pure function initial_positions(input) result(text)
    type(scene_input), intent(in) :: input
    character(len=2 * fmt_width + 16) :: text     ! blank padded: callers trim
    text = 'x1 = ' // trim(fmt(input%value(i_x1)))
    if (input%given(i_m2)) text = trim(text) // ', x2 = ' // trim(fmt(input%value(i_x2)))
  end function initial_positions

  !> Value i, or default when it is not given.
  pure real(wp) function value_or(input, i, default)
    type(scene_input), intent(in) :: input
    integer, intent(in) :: i
    real(wp), intent(in) :: default
    value_or = default
    if (input%given(i)) value_or = input%value(i)
  end function value_or

  !> Constraint k's offset as the input gives it (gap = normal . x + offset).
  pure real(wp) function offset_of(input, k)
    type(scene_input), intent(in) :: input
    integer, intent(in) :: k
    offset_of = offset_sign(k) * limit_value(input, k)
  end function offset_of

  !> Validate and build the model. tables(i) holds f_i's table when the input names one;
  !> records are the scene's contacts and elements (impact1d_chain's input_records).
  !> validated: the caller has run validate(input, .true.) (prepare_scene, which must before
  !> it makes the records): not run again (8,000 instructions and 16 allocations a call).
  subroutine build_scene(input, tables, records, scene, error, validated)
    type(scene_input), intent(in) :: input
    type(table_type), intent(in) :: tables(:)   !< (N) body i's force table (when it has one)
    type(mechanism_records), intent(in) :: records
    type(scene_type), intent(out) :: scene
    type(error_type), allocatable, intent(out) :: error
    logical, intent(in), optional :: validated
    logical :: again

    again = .true.
    if (present(validated)) again = .not. validated
    if (again) call validate(input, .true., error)
    if (allocated(error)) return
    scene%title = trim(input%text(i_title)%s)
    scene%method = 'event'
    if (len_trim(input%text(i_method)%s) > 0) scene%method = trim(input%text(i_method)%s)
    ! One or two bodies from the tutorial's scalars, more from the arrays; any number runs on
    ! the N-body engine (impact1d_nbody_solver), or on the vissim method's scheme
    ! (impact1d_vissim).
    if (is_nbody(input)) then
      call set_chain_bodies(input, tables, scene)
    else
      call set_bodies(input, tables, scene)
    end if
    if (records%n_sines > 0) call scene%forcing%set_sines(records%sine_body, records%sine_amp, &
      records%sine_period, records%sine_phase)
    call scene%forcing%set_varies()
    if (scene%method == 'vissim') call refuse_stops(records, 'need method = ''event'' (the vissim ' // &
      'method is the tutorial''s scheme, with rigid contacts only)', error)
    if (allocated(error)) return
    call set_laws(input, scene, error)
    if (allocated(error)) return
    call set_frictions(records, scene, error)
    if (allocated(error)) return
    call set_records(input, records, scene)
    if (scene%drives%n > 0) call refuse_drives(scene, error)
    if (allocated(error)) return
    call set_gears(records, scene, error)
    if (allocated(error)) return
    call set_rows(scene)
    if (scene%belt_moves) call refuse_belt_contacts(scene, error)
    if (allocated(error)) return
    call set_springs(scene)
    scene%stage_powers = scene%drives%n > 0 .or. scene%belts .or. scene%stribeck .or. scene%n_stops > 0 .or. &
      scene%geared
    scene%gap_terms = scene%drives%n > 0 .or. scene%geared
    scene%held_motion = scene%drives%n > 0 .or. scene%belt_moves

    scene%t_end = input%value(i_t_end)
    scene%dt = input%value(i_dt)
    scene%dt_out = scene%dt
    if (input%given(i_dt_out)) scene%dt_out = input%value(i_dt_out)
    if (input%given(i_zero_vel)) scene%zero_velocity = input%value(i_zero_vel)
    scene%warnings = ''
    ! The modes are a dense eigenproblem (N^3): past max_modal_bodies the step is not checked.
    if (scene%springs%present .and. scene%n_bodies <= max_modal_bodies) then
      call check_step(scene, input%text(i_substeps)%s == 'auto', error)
    else if (scene%springs%present) then
      scene%warnings = 'the step was not checked against the springs'' modes (more than ' // &
        trim(fmt(max_modal_bodies)) // ' bodies): choose dt well below 2 / w of the stiffest spring'
    end if
    if (allocated(error)) return
    scene%events = events_kept(input)
    if (input%given(i_max_impulses)) scene%max_impulses = int(input%value(i_max_impulses))
    if (input%given(i_max_step_events)) scene%max_step_events = int(input%value(i_max_step_events))
    if (input%given(i_max_events)) scene%max_events = int(input%value(i_max_events))
    ! (validate keeps the count within max_rows, a default integer)
    scene%n_samples = int(row_count(scene%t_end, scene%dt_out))
  end subroutine build_scene

  !> The friction laws the arrays belt_v, v_s, c_v name (kept as arrays for any N), each
  !> allocated only when named; the vissim method has none of them.
  subroutine set_laws(input, scene, error)
    type(scene_input), intent(in) :: input
    type(scene_type), intent(inout) :: scene
    type(error_type), allocatable, intent(inout) :: error
    integer :: i, n
    real(wp) :: g
    n = scene%n_bodies
    scene%belts = input%chain%array(a_belt_v)%n > 0 .or. input%chain%array(a_belt_amp)%n > 0
    scene%stribeck = input%chain%array(a_v_s)%n > 0 .or. input%chain%array(a_c_v)%n > 0
    if (.not. (scene%belts .or. scene%stribeck)) return
    if (scene%method == 'vissim') then
      call raise(error, status_input, "method = 'vissim' is the tutorial's fixed-step scheme: a scene " // &
        'with a moving friction surface (belt_v, belt_amp) or Stribeck friction (v_s, c_v) runs with method = ''event''')
      return
    end if
    g = value_or(input, i_g, default_gravity)
    if (scene%belts) scene%body_belt = [(array_value(input%chain, a_belt_v, i, 0.0_wp) + 0.0_wp, i = 1, n)]
    if (input%chain%array(a_belt_amp)%n > 0) then
      scene%body_belt_amp = [(array_value(input%chain, a_belt_amp, i, 0.0_wp) + 0.0_wp, i = 1, n)]
      scene%body_belt_phase = [(array_value(input%chain, a_belt_phase, i, 0.0_wp) + 0.0_wp, i = 1, n)]
      scene%body_belt_omega = [(angular_frequency(array_value(input%chain, a_belt_period, i, 1.0_wp)), i = 1, n)]
      ! (belt_amp = 0 everywhere is the constant belt: the same path, the same bits)
      scene%belt_moves = any(scene%body_belt_amp /= 0.0_wp)
    end if
    if (scene%stribeck) then
      scene%body_v_s = [(array_value(input%chain, a_v_s, i, 0.0_wp), i = 1, n)]
      scene%body_viscous = [(array_value(input%chain, a_c_v, i, 0.0_wp) * scene%body_mass(i) * g, i = 1, n)]
    end if
  end subroutine set_laws

  !> speed plus body i's belt's sine at t, belt_amp sin(belt_omega t + belt_phase) (0 on a
  !> belt of constant speed): scene_type's belt_sine.
  pure real(wp) function add_belt_sine(scene, i, t, speed_in) result(speed)
    type(scene_type), intent(in) :: scene
    integer, intent(in) :: i
    real(wp), intent(in) :: t
    real(wp), value :: speed_in
    speed = speed_in
    if (scene%body_belt_amp(i) /= 0.0_wp) speed = speed + scene%body_belt_amp(i) * &
      sin(scene%body_belt_omega(i) * t + scene%body_belt_phase(i))
  end function add_belt_sine

  !> A body on a belt of sine speed (belt_amp /= 0) may not be an end of a &friction record:
  !> stuck, it accelerates with its own belt, which the mode solve takes body by body (a
  !> cluster solve holds its bodies in one frame). (Its contacts are refused where one is held
  !> between it stuck and a body that would ride its belt: impact1d_nbody_event's
  !> refuse_held_belts.)
  subroutine refuse_belt_contacts(scene, error)
    type(scene_type), intent(in) :: scene
    type(error_type), allocatable, intent(inout) :: error
    integer :: k, e, i
    do k = 1, scene%n_frictions
      do e = 1, 2
        i = scene%friction_body(e, k)
        if (scene%body_belt_amp(i) /= 0.0_wp) then
          call raise(error, status_input, 'a body on a belt of sine speed (belt_amp) cannot have friction ' // &
            'contacts yet, but body ' // trim(fmt(i)) // ' is an end of the &friction record ' // &
            trim(scene%friction_name(k)) // ' (docs/method.md section 12)')
          return
        end if
      end do
    end do
  end subroutine refuse_belt_contacts

  !> The &friction records (friction contacts between two bodies), which only the N-body
  !> engine runs (impact1d_solver's run): not the vissim method.
  subroutine set_frictions(records, scene, error)
    type(mechanism_records), intent(in) :: records
    type(scene_type), intent(inout) :: scene
    type(error_type), allocatable, intent(inout) :: error
    scene%n_frictions = records%n_frictions
    if (scene%n_frictions == 0) return
    if (scene%method == 'vissim') then
      call raise(error, status_input, "method = 'vissim' is the tutorial's fixed-step scheme: a scene " // &
        'with friction between two bodies (&friction) runs with method = ''event''')
      return
    end if
    scene%friction_body = records%friction_body
    scene%friction_slide = records%friction_slide
    scene%friction_static = records%friction_static
    scene%friction_name = records%friction_name
  end subroutine set_frictions

  !> The records' gear ratios (impact1d_chain's gear_ratio checked each record): a scene
  !> with one other than 1 is geared, which only the N-body engine runs, so far without the
  !> vissim method, moving grounds, friction between bodies (&friction) or the friction laws
  !> (refused by name: moving frames and friction contacts take groups as moving alike).
  !> Each body's own Coulomb friction against the ground (mu, mus) is allowed: a geared
  !> group slides and sticks as one (docs/method.md section 14).
  subroutine set_gears(records, scene, error)
    type(mechanism_records), intent(in) :: records
    type(scene_type), intent(inout) :: scene
    type(error_type), allocatable, intent(inout) :: error
    character(len=:), allocatable :: what
    scene%contact_ratio = records%contact_ratio
    scene%element_ratio = records%element_ratio
    scene%geared = any(records%contact_ratio /= 1.0_wp) .or. any(records%element_ratio /= 1.0_wp)
    if (.not. scene%geared) return
    what = ''
    if (scene%method == 'vissim') what = "method = 'vissim' (the tutorial's scheme)"
    if (scene%drives%n > 0) what = 'a moving ground (ground_v, ground_amp, ground_table, x_left_v ...)'
    if (scene%n_frictions > 0) what = 'friction between bodies (&friction)'
    if (scene%belts .or. scene%stribeck) what = 'belt_v, belt_amp, v_s or c_v'
    if (len(what) > 0) call raise(error, status_input, 'a gear ratio (ratio other than 1) cannot be ' // &
      'combined with ' // what // ' yet: geared scenes run on the N-body engine''s event method, ' // &
      'on still grounds, with friction only of each body against the ground (mu, mus)')
  end subroutine set_gears

  !> A scene with a moving ground runs on the N-body engine (whatever its N), which has no
  !> vissim method.
  subroutine refuse_drives(scene, error)
    type(scene_type), intent(in) :: scene
    type(error_type), allocatable, intent(inout) :: error
    if (scene%method == 'vissim') call raise(error, status_input, "method = 'vissim' is the tutorial's " // &
      'fixed-step scheme: a scene with a moving ground (ground_v, ground_amp) runs with method = ''event''')
  end subroutine refuse_drives

  !> A scene whose engine has no compliant stops: the first &contact record with k named
  !> in the message (why: what the engine lacks).
  subroutine refuse_stops(records, why, error)
    type(mechanism_records), intent(in) :: records
    character(len=*), intent(in) :: why
    type(error_type), allocatable, intent(inout) :: error
    integer :: j
    do j = 1, records%n_contacts
      if (records%contact_k(j) > 0.0_wp) then
        call raise(error, status_input, 'the &contact ''' // trim(records%contact_name(j)) // ''' has k = ' // &
          trim(fmt(records%contact_k(j))) // ': compliant stops ' // why)
        return
      end if
    end do
  end subroutine refuse_stops

  !> The bodies (N: 2 with m2, else 1) and their forces but the &sine records' (build_scene's).
  subroutine set_bodies(input, tables, scene)
    type(scene_input), intent(in) :: input
    type(table_type), intent(in) :: tables(:)
    type(scene_type), intent(inout) :: scene
    integer :: i, k, n
    real(wp) :: g
    n = merge(2, 1, input%given(i_m2))
    scene%n_bodies = n
    allocate(scene%body_mass(n), scene%body_friction(n), scene%body_static(n), scene%body_x0(n), &
      scene%body_v0(n))
    scene%body_mass = input%value(i_m1:i_m1 + n - 1)
    g = default_gravity
    if (input%given(i_g)) g = input%value(i_g)
    scene%body_friction = 0.0_wp
    do i = 1, n
      if (input%given(i_mu1 + i - 1)) scene%body_friction(i) = input%value(i_mu1 + i - 1) * scene%body_mass(i) * g
    end do
    scene%body_friction = max(scene%body_friction, 0.0_wp)
    scene%body_static = scene%body_friction
    do i = 1, n
      if (input%given(i_mus1 + i - 1)) scene%body_static(i) = input%value(i_mus1 + i - 1) * scene%body_mass(i) * g
    end do
    scene%body_static = max(scene%body_static, scene%body_friction)
    ! Inputs of -0 enter as +0 (the limits too, in build_scene): sums over bodies and contacts
    ! drop absent terms exactly only when nothing they meet is -0, and a root formula takes
    ! the sign of a zero (docs/architecture.md, "Signed zeros").
    scene%body_x0(1) = input%value(i_x1) + 0.0_wp
    scene%body_v0 = 0.0_wp
    if (input%given(i_v1)) scene%body_v0(1) = input%value(i_v1) + 0.0_wp
    if (n == 2) then
      scene%body_x0(2) = input%value(i_x2) + 0.0_wp
      if (input%given(i_v2)) scene%body_v0(2) = input%value(i_v2) + 0.0_wp
    end if
    call scene%forcing%allocate_bodies(n)
    do i = 1, n
      if (input%given(i_f1 + i - 1)) scene%forcing%constant(i) = input%value(i_f1 + i - 1)
      scene%forcing%has_table(i) = len_trim(input%text(i_f1_table + i - 1)%s) > 0
      if (scene%forcing%has_table(i)) scene%forcing%table(i) = tables(i)
      k = i_f1_amp + 3 * (i - 1)
      scene%forcing%has_sine(i) = input%given(k)
      if (scene%forcing%has_sine(i)) then
        scene%forcing%amp(i) = input%value(k)
        scene%forcing%omega(i) = angular_frequency(input%value(k + 1))
        if (input%given(k + 2)) scene%forcing%phase(i) = input%value(k + 2)
      end if
    end do
  end subroutine set_bodies

  !> The bodies of a scene written as arrays of N > 2 (impact1d_fields' chain_input): body i's
  !> values at position i, mu and f 0 and mus = mu when absent, v 0; tables(i) its force table.
  subroutine set_chain_bodies(input, tables, scene)
    type(scene_input), intent(in) :: input
    type(table_type), intent(in) :: tables(:)
    type(scene_type), intent(inout) :: scene
    integer :: i, n
    real(wp) :: g, mu
    n = input%chain%n_bodies
    scene%n_bodies = n
    allocate(scene%body_mass(n), scene%body_friction(n), scene%body_static(n), scene%body_x0(n), &
      scene%body_v0(n))
    g = value_or(input, i_g, default_gravity)
    call scene%forcing%allocate_bodies(n)
    do i = 1, n
      associate (chain => input%chain)
        scene%body_mass(i) = array_value(chain, a_m, i, 1.0_wp)
        mu = array_value(chain, a_mu, i, 0.0_wp)
        scene%body_friction(i) = max(mu * scene%body_mass(i) * g, 0.0_wp)
        scene%body_static(i) = max(array_value(chain, a_mus, i, mu) * scene%body_mass(i) * g, &
          scene%body_friction(i))
        ! (-0 enters as +0: docs/architecture.md, "Signed zeros")
        scene%body_x0(i) = array_value(chain, a_x, i, 0.0_wp) + 0.0_wp
        scene%body_v0(i) = array_value(chain, a_v, i, 0.0_wp) + 0.0_wp
        scene%forcing%constant(i) = array_value(chain, a_f, i, 0.0_wp)
        scene%forcing%has_table(i) = .false.
        if (chain%array(a_f_table)%n >= i) scene%forcing%has_table(i) = len_trim(chain%array(a_f_table)%t(i)%s) > 0
        if (scene%forcing%has_table(i)) scene%forcing%table(i) = tables(i)
        scene%forcing%has_sine(i) = chain%array(a_f_amp)%n >= i
        if (scene%forcing%has_sine(i)) then
          scene%forcing%amp(i) = array_value(chain, a_f_amp, i, 0.0_wp)
          scene%forcing%omega(i) = 2.0_wp * acos(-1.0_wp) / array_value(chain, a_f_period, i, 1.0_wp)
          scene%forcing%phase(i) = array_value(chain, a_f_phase, i, 0.0_wp)
        end if
      end associate
    end do
  end subroutine set_chain_bodies

  !> The model's contact and element records: impact1d_chain's input_records (the walls,
  !> the slot, then the &contact records; the springs k1, k2, k12, then the &spring records:
  !> the orders of docs/nbody-plan.md B4, B5). A limit of -0 enters as +0 (docs/architecture.md,
  !> "Signed zeros"). Which of the elements the scene names as springs or dampers sets the
  !> output's pe and damping_loss columns (springs%has_spring, has_damper).
  subroutine set_records(input, records, scene)
    type(scene_input), intent(in) :: input
    type(mechanism_records), intent(in) :: records
    type(scene_type), intent(inout) :: scene
    logical :: named(2)
    call allocate_contacts(scene, records%n_contacts)
    scene%contact_body = records%contact_body
    scene%contact_has = records%contact_has
    scene%contact_limit = records%contact_limit + 0.0_wp
    scene%contact_restitution = records%contact_restitution
    scene%contact_name = records%contact_name
    scene%contact_k = records%contact_k
    scene%contact_c = records%contact_c
    scene%n_elements = records%n_elements
    scene%element_body = records%element_body
    scene%element_k = records%element_k
    scene%element_c = records%element_c
    scene%element_rest = records%element_rest
    call set_drives(records, scene)
    named = springs_named(input)
    scene%springs%has_spring = named(1)
    scene%springs%has_damper = named(2)
  end subroutine set_records

  !> The records' moving grounds as drives (contacts', then elements', in record order): a
  !> record that names any ground_* field has one, even if all are 0 (a ground that moves
  !> at 0 m/s: the same motion on the N-body engine, which tests compare).
  subroutine set_drives(records, scene)
    type(mechanism_records), intent(in) :: records
    type(scene_type), intent(inout) :: scene
    integer :: j
    allocate(scene%contact_drive(records%n_contacts), scene%element_drive(records%n_elements))
    scene%contact_drive = 0
    scene%element_drive = 0
    if (.not. allocated(records%contact_ground)) return
    do j = 1, records%n_contacts
      if (.not. records%contact_moves(j)) cycle
      if (allocated(records%contact_table_path(j)%s)) then
        call add_drive(records%contact_ground(:, j), scene%contact_drive(j), records%contact_table(j))
      else
        call add_drive(records%contact_ground(:, j), scene%contact_drive(j))
      end if
    end do
    do j = 1, records%n_elements
      if (.not. records%element_moves(j)) cycle
      if (allocated(records%element_table_path(j)%s)) then
        call add_drive(records%element_ground(:, j), scene%element_drive(j), records%element_table(j))
      else
        call add_drive(records%element_ground(:, j), scene%element_drive(j))
      end if
    end do

  contains

    !> ground = (v, amp, period, phase) and the table, if any: drive d.
    subroutine add_drive(ground, d, table)
      real(wp), intent(in) :: ground(:)
      integer, intent(out) :: d
      type(table_type), intent(in), optional :: table
      real(wp) :: omega
      omega = 0.0_wp
      if (ground(3) > 0.0_wp .and. ground(2) /= 0.0_wp) omega = angular_frequency(ground(3))
      call scene%drives%add(ground(1), ground(2), omega, ground(4), table)
      d = scene%drives%n
    end subroutine add_drive
  end subroutine set_drives

  !> Whether the scene names a stiffness, and a damping: the tutorial's k1, k2, k12 (c1, c2,
  !> c12), a &spring record's k (c) or a compliant &contact's k (c). They decide the pe and damping_loss columns.
  pure function springs_named(input) result(named)
    type(scene_input), intent(in) :: input
    logical :: named(2)
    integer :: r
    named = [any(input%given(spring_index)), any(input%given(spring_index + 2))]
    ! A compliant stop's k stores energy (pe), its c dissipates (damping_loss).
    if (allocated(input%chain%contacts)) then
      do r = 1, size(input%chain%contacts)
        named = named .or. input%chain%contacts(r)%given([r_stop_k, r_stop_c])
      end do
    end if
    if (.not. allocated(input%chain%springs)) return
    do r = 1, size(input%chain%springs)
      named = named .or. input%chain%springs(r)%given([r_k, r_c])
    end do
  end function springs_named

  !> Whether a record names its ground's motion (ground_v ...), or the walls theirs
  !> (x_left_v ...), or the bodies a moving friction surface (belt_v): the drive_work column.
  pure logical function ground_named(input)
    type(scene_input), intent(in) :: input
    integer :: r
    ground_named = any(input%given(i_x_left_v:i_x_right_v + 3)) .or. input%chain%array(a_belt_v)%n > 0 .or. &
      input%chain%array(a_belt_amp)%n > 0 .or. &
      len_trim(input%text(i_x_left_table)%s) > 0 .or. len_trim(input%text(i_x_right_table)%s) > 0
    if (allocated(input%chain%contacts)) then
      do r = 1, size(input%chain%contacts)
        ground_named = ground_named .or. any(input%chain%contacts(r)%given(r_ground_v:r_ground_table))
      end do
    end if
    if (.not. allocated(input%chain%springs)) return
    do r = 1, size(input%chain%springs)
      ground_named = ground_named .or. any(input%chain%springs(r)%given(r_spring_ground_v:r_spring_ground_table))
    end do
  end function ground_named

  !> Whether the forces depend on the state: element records (the engine reads them
  !> themselves, impact1d_elements) or compliant stops (their rows, elements of the same kind
  !> while engaged).
  subroutine set_springs(scene)
    type(scene_type), intent(inout) :: scene
    scene%springs%present = scene%n_elements > 0 .or. scene%n_stops > 0
  end subroutine set_springs

  !> Room for nc contact records, none of their limits present yet.
  subroutine allocate_contacts(scene, nc)
    type(scene_type), intent(inout) :: scene
    integer, intent(in) :: nc
    scene%n_contacts = nc
    allocate(scene%contact_body(2, nc), scene%contact_has(2, nc), scene%contact_limit(2, nc), &
      scene%contact_restitution(2, nc), scene%contact_name(nc), scene%contact_k(nc), scene%contact_c(nc), &
      scene%contact_ratio(nc))
    scene%contact_ratio = 1.0_wp
    scene%contact_body = 0
    scene%contact_has = .false.
    scene%contact_limit = 0.0_wp
    scene%contact_restitution = 1.0_wp
    scene%contact_name = ''
    scene%contact_k = 0.0_wp
    scene%contact_c = 0.0_wp
  end subroutine allocate_contacts

  !> The rows from the contact records: one per present limit, in record order, the lower
  !> limit first (the row order decides ties, docs/nbody-plan.md B4). A lower limit's gap
  !> is (x_b - x_a) - d_min, an upper one's d_max - (x_b - x_a) (x_b - n x_a with a gear
  !> ratio n); a ground end has no coefficient. The two limits of a rigid link (d_min = d_max) are each other's partner.
  subroutine set_rows(scene)
    type(scene_type), intent(inout) :: scene
    integer :: j, e, r, nr, pass
    real(wp) :: sgn
    logical :: suffix
    nr = count(scene%contact_has)
    scene%n_stops = count(scene%contact_has .and. spread(scene%contact_k > 0.0_wp, 1, 2))
    scene%n_rows = nr - scene%n_stops
    allocate(scene%row_contact(nr), scene%row_body(2, nr), scene%row_normal(2, nr), scene%row_offset(nr), &
      scene%row_restitution(nr), scene%row_partner(nr), scene%row_name(nr), scene%row_k(nr), scene%row_c(nr), &
      scene%row_drive(nr))
    scene%row_partner = 0
    scene%row_drive = 0
    r = 0
    ! The rigid records' rows, then the compliant stops' (pass 2), each in record order.
    do pass = 1, 2
      do j = 1, scene%n_contacts
        if ((scene%contact_k(j) > 0.0_wp) .neqv. (pass == 2)) cycle
        suffix = all(scene%contact_has(:, j)) .or. scene%contact_name(j) == 'slot'
        do e = 1, 2
          if (.not. scene%contact_has(e, j)) cycle
          r = r + 1
          sgn = merge(1.0_wp, -1.0_wp, e == 1)
          scene%row_contact(r) = j
          scene%row_body(:, r) = scene%contact_body(:, j)
          ! (a gear ratio n: the gap of x_b - n x_a, normal (-n, 1) or (n, -1))
          scene%row_normal(:, r) = merge([-sgn * scene%contact_ratio(j), sgn], [0.0_wp, 0.0_wp], &
            scene%contact_body(:, j) /= 0)
          scene%row_offset(r) = -sgn * scene%contact_limit(e, j)
          scene%row_restitution(r) = scene%contact_restitution(e, j)
          scene%row_k(r) = scene%contact_k(j)
          scene%row_c(r) = scene%contact_c(j)
          scene%row_name(r) = scene%contact_name(j)
          if (allocated(scene%contact_drive)) scene%row_drive(r) = scene%contact_drive(j)
          if (suffix) scene%row_name(r) = trim(scene%contact_name(j)) // trim(merge('_min', '_max', e == 1))
        end do
        if (all(scene%contact_has(:, j)) .and. pass == 1) then
          if (scene%contact_limit(1, j) == scene%contact_limit(2, j)) then
            scene%row_partner(r - 1) = r
            scene%row_partner(r) = r - 1
          end if
        end if
      end do
    end do
  end subroutine set_rows


  !> A matrix assembled on x_b - x_a (assemble) turned into the geared elements' own: an
  !> element of coefficient q on x_b - n x_a adds q g g' with g = (-n, 1) on (a, b), so its
  !> (a, a) entry gains q (n^2 - 1) and its (a, b), (b, a) entries -q (n - 1).
  pure subroutine gear_matrix(scene, coefficient, matrix)
    type(scene_type), intent(in) :: scene
    real(wp), intent(in) :: coefficient(:)
    real(wp), intent(inout) :: matrix(:, :)
    integer :: j
    do j = 1, scene%n_elements
      associate (a => scene%element_body(1, j), b => scene%element_body(2, j), n => scene%element_ratio(j))
        if (a == 0 .or. n == 1.0_wp) cycle
        matrix(a, a) = matrix(a, a) + coefficient(j) * (n**2 - 1.0_wp)
        matrix(a, b) = matrix(a, b) - coefficient(j) * (n - 1.0_wp)
        matrix(b, a) = matrix(a, b)
      end associate
    end do
  end subroutine gear_matrix

  !> RK4's step against the modes of the springs and dampers (impact1d_stability): past the
  !> largest stable step the numbers would be garbage (positions to 1e76 with a normal exit),
  !> so the scene is refused; a stable step that is coarse for the fastest mode gets a warning
  !> with the error RK4 makes on that mode (a spring at w dt = 1 loses most of its energy in a
  !> few periods without it). Each message names the element that sets the fastest rate.
  !> With substeps (&run substeps = 'auto') a dt coarse for the fastest mode is divided
  !> instead: the step becomes dt / n with n the fewest that bring |lambda| h to coarse_rate
  !> (samples stay every dt_out, its default the dt given).
  subroutine check_step(scene, substeps, error)
    type(scene_type), intent(inout) :: scene
    logical, intent(in) :: substeps
    type(error_type), allocatable, intent(inout) :: error
    real(wp) :: k(scene%n_bodies, scene%n_bodies), c(scene%n_bodies, scene%n_bodies), h_stable
    complex(wp) :: lambda(2 * scene%n_bodies), fastest
    logical :: ok
    integer :: j

    if (scene%n_stops > 0) then
      ! The compliant stops as if engaged (springs and dampers between their rows' ends).
      associate (stops => [(j, j = scene%n_rows + 1, scene%n_rows + scene%n_stops)])
        call assemble(reshape([scene%element_body, scene%row_body(:, stops)], [2, scene%n_elements + &
          scene%n_stops]), [scene%element_k, scene%row_k(stops)], k)
        call assemble(reshape([scene%element_body, scene%row_body(:, stops)], [2, scene%n_elements + &
          scene%n_stops]), [scene%element_c, scene%row_c(stops)], c)
      end associate
    else
      call assemble(scene%element_body, scene%element_k, k)
      call assemble(scene%element_body, scene%element_c, c)
    end if
    if (scene%geared) then
      call gear_matrix(scene, scene%element_k, k)
      call gear_matrix(scene, scene%element_c, c)
    end if
    call linear_modes(scene%body_mass, c, k, lambda, ok)
    if (.not. ok) then
      call raise(error, status_input, 'the modes of the springs and dampers could not be found ' // &
        '(eigenvalues did not converge): please report the scene')
      return
    end if
    h_stable = minval([(stable_step(lambda(j)), j = 1, size(lambda))])
    fastest = lambda(maxloc(abs(lambda), 1))
    if (substeps .and. abs(fastest) * scene%dt > coarse_rate) then
      scene%substeps = ceiling(min(abs(fastest) * scene%dt / coarse_rate, real(huge(1), wp)))
      if (scene%dt / scene%substeps < clock_resolution_ulps * spacing(scene%t_end)) then
        call raise(error, status_input, 'substeps = ''auto'' would step dt = ' // trim(fmt(scene%dt)) // &
          ' in ' // trim(fmt(scene%substeps)) // ' steps, below the clock''s resolution at t_end: the ' // &
          'fastest mode (' // trim(mode_text(fastest)) // ', set by ' // trim(fastest_element(scene)) // &
          ') is too fast for this run')
        return
      end if
      scene%dt = scene%dt / scene%substeps
    end if
    if (scene%dt > h_stable) then
      call raise(error, status_input, 'dt = ' // trim(fmt(scene%dt)) // ' is past RK4''s stability ' // &
        'limit for this scene''s springs and dampers: its fastest mode (' // trim(mode_text(fastest)) // &
        ', set by ' // trim(fastest_element(scene)) // ') needs dt <= ' // trim(fmt(h_stable)) // &
        ' (the numbers would grow without bound): lower dt, or set &run substeps = ''auto''')
    else if (abs(fastest) * scene%dt > coarse_rate) then
      scene%warnings = 'dt = ' // trim(fmt(scene%dt)) // ' is coarse for this scene''s fastest mode (' // &
        trim(mode_text(fastest)) // ', set by ' // trim(fastest_element(scene)) // '): |lambda| dt = ' // &
        trim(fmt(abs(fastest) * scene%dt)) // ' > ' // trim(fmt(coarse_rate)) // ', so RK4''s relative ' // &
        'error on it is about ' // trim(two_digits(mode_error(fastest, scene%dt))) // ' over each of its ' // &
        trim(merge('periods        ', 'time constants ', aimag(fastest) /= 0.0_wp)) // &
        ' (order dt^4: halve dt for 1/16 of it)'
    end if
  end subroutine check_step

  !> An estimate, to two digits ('5.1E-02').
  pure function two_digits(x) result(text)
    real(wp), intent(in) :: x
    character(len=12) :: text     ! blank padded: callers trim
    write(text, '(es12.1)') x
    text = adjustl(text)
  end function two_digits

  !> 'w = 31.6 rad/s, damping rate 0.5 1/s' for a mode lambda (for messages).
  pure function mode_text(lambda) result(text)
    complex(wp), intent(in) :: lambda
    character(len=2 * fmt_width + 40) :: text     ! blank padded: callers trim
    if (aimag(lambda) /= 0.0_wp .and. -real(lambda, wp) <= 1024.0_wp * eps_wp * abs(lambda)) then
      text = 'w = ' // trim(fmt(abs(aimag(lambda)))) // ' rad/s, undamped'   ! (a rounding-level real part)
    else if (aimag(lambda) /= 0.0_wp) then
      text = 'w = ' // trim(fmt(abs(aimag(lambda)))) // ' rad/s, damping rate ' // &
        trim(fmt(-real(lambda, wp))) // ' 1/s'
    else
      text = 'decay rate ' // trim(fmt(-real(lambda, wp))) // ' 1/s'
    end if
  end function mode_text

  !> The spring or damper with the fastest rate of its own ('k12 = 1e4'): sqrt(k / m) or c / m
  !> with m the mass it moves (the body's on a ground element, the reduced mass between
  !> bodies). Named as the tutorial names
  !> it: k<b> or c<b> to the ground, k<a><b> or c<a><b> between bodies.
  pure function fastest_element(scene) result(text)
    type(scene_type), intent(in) :: scene
    character(len=fmt_width + name_len + 24) :: text     ! blank padded: callers trim
    real(wp) :: rate(2 * scene%n_elements), stop_rate(2 * scene%n_stops), mass
    character(len=8) :: ends
    integer :: j, ne, ns, r
    ne = scene%n_elements
    ns = scene%n_stops
    do j = 1, ne
      mass = ends_mass(scene, scene%element_body(:, j))
      rate([j, ne + j]) = [sqrt(scene%element_k(j) / mass), scene%element_c(j) / mass]
    end do
    do j = 1, ns
      r = scene%n_rows + j
      mass = ends_mass(scene, scene%row_body(:, r))
      stop_rate([j, ns + j]) = [sqrt(scene%row_k(r) / mass), scene%row_c(r) / mass]
    end do
    ! A compliant stop sets it when it is faster than every element (as if engaged).
    if (ns > 0) then
      if (ne == 0 .or. maxval(stop_rate) > maxval(rate)) then
        j = maxloc(stop_rate, 1)
        if (j > ns) j = j - ns
        r = scene%n_rows + j
        text = 'the stop ''' // trim(scene%row_name(r)) // ''' (k = ' // trim(fmt(scene%row_k(r))) // &
          ', c = ' // trim(fmt(scene%row_c(r))) // ')'
        return
      end if
    end if
    j = maxloc(rate, 1)
    if (j > ne) j = j - ne
    write(ends, '(i0)') scene%element_body(2, j)
    if (scene%element_body(1, j) > 0) write(ends, '(i0, i0)') scene%element_body(:, j)
    if (maxloc(rate, 1) <= ne) then
      text = 'k' // trim(ends) // ' = ' // trim(fmt(scene%element_k(j)))
    else
      text = 'c' // trim(ends) // ' = ' // trim(fmt(scene%element_c(j)))
    end if
  end function fastest_element

  !> The mass an element or stop between ends (a, b) moves: the body's on the ground, the
  !> reduced mass between two bodies.
  pure real(wp) function ends_mass(scene, ends) result(mass)
    type(scene_type), intent(in) :: scene
    integer, intent(in) :: ends(2)
    associate (m => scene%body_mass, a => ends(1), b => ends(2))
      mass = m(b)
      if (a > 0) mass = 1.0_wp / (1.0_wp / m(a) + 1.0_wp / m(b))
    end associate
  end function ends_mass

  !> The step toward a stop with `remaining` time to it: dt, or what is left when that is
  !> less. No sliver steps: a step that would end just short of the stop goes to it.
  pure real(wp) function step_length(dt, remaining) result(h)
    real(wp), intent(in) :: dt, remaining
    h = min(dt, remaining)
    if (remaining - h <= 1.0e-9_wp * dt) h = remaining
  end function step_length

  !> Output rows of a run: samples at j dt_out from t = 0, and at t_end when it is off that
  !> grid (within 1e-9 of a step it is on it). Real: a refused scene's count may exceed any
  !> integer.
  pure real(wp) function row_count(t_end, dt_out)
    real(wp), intent(in) :: t_end, dt_out
    real(wp) :: ratio
    ratio = t_end / dt_out
    row_count = anint(ratio) + 1.0_wp
    if (abs(ratio - anint(ratio)) > 1.0e-9_wp * max(1.0_wp, ratio)) row_count = aint(ratio) + 2.0_wp
    ! The grid always ends at t_end (t_end > 0): a dt_out a billion times t_end rounds the
    ! ratio to a grid of the t = 0 row alone.
    row_count = max(2.0_wp, row_count)
  end function row_count

  !> A count held in a real, written as an integer (10000001, not 10000001.0).
  pure function fmt_count(count) result(text)
    real(wp), intent(in) :: count
    character(len=fmt_width) :: text
    text = fmt(count)
    if (count < 0.5_wp * real(huge(1_int64), wp)) text = fmt(int(count, int64))
  end function fmt_count

  !> Text field i (i_title, i_f1_table, i_f2_table, i_method) := text, kept whole.
  pure subroutine set_text(input, i, text)
    type(scene_input), intent(inout) :: input
    integer, intent(in) :: i
    character(len=*), intent(in) :: text
    input%text(i)%s = text
  end subroutine set_text

  !> Time of output sample j (0-based): j dt_out, and t_end for the last one.
  pure real(wp) function sample_time(scene, j)
    type(scene_type), intent(in) :: scene
    integer, intent(in) :: j
    if (j == scene%n_samples - 1) then
      sample_time = scene%t_end
    else
      sample_time = j * scene%dt_out
    end if
  end function sample_time

  !> Whether constraint k exists: as the scene names it, and the bodies' meeting (the link's
  !> lower limit at d_min = 0) always: two bodies on one line cannot pass each other.
  pure logical function has_limit(input, k)
    type(scene_input), intent(in) :: input
    integer, intent(in) :: k
    has_limit = input%given(limit_index(k)) .or. (k == i_slot_min .and. input%given(i_m2))
  end function has_limit

  !> The contacts' normals: with one body (no m2) both walls hold body 1.
  pure function contact_normals(input) result(nrm)
    type(scene_input), intent(in) :: input
    real(wp) :: nrm(2, n_limits)
    nrm = two_body_normal
    if (.not. input%given(i_m2)) nrm = one_body_normal
  end function contact_normals

  !> Limit of constraint k: as given, or 0 for the bodies' meeting.
  pure real(wp) function limit_value(input, k)
    type(scene_input), intent(in) :: input
    integer, intent(in) :: k
    limit_value = 0.0_wp
    if (input%given(limit_index(k))) limit_value = input%value(limit_index(k))
  end function limit_value

  !> Index of the variable that names constraint k (its limit); the restitution follows it.
  pure integer function limit_index(k)
    integer, intent(in) :: k
    integer, parameter :: indices(n_limits) = [i_x_left, i_x_right, i_d_min, i_d_max]
    limit_index = indices(k)
  end function limit_index

  !> Where wall k's prescribed motion puts it at t = 0 (x_left_amp sin(x_left_phase): its
  !> sine's; 0 without one), added to its limit.
  pure real(wp) function wall_start(input, k)
    type(scene_input), intent(in) :: input
    integer, intent(in) :: k
    integer :: first
    wall_start = 0.0_wp
    first = merge(i_x_left_v, i_x_right_v, k == i_left)
    if (input%given(first + 1) .and. input%given(first + 2)) wall_start = input%value(first + 1) * &
      sin(value_or(input, first + 3, 0.0_wp))
  end function wall_start

  !> gap = normal . x + offset_sign * limit (left: x1 - x_left; right: x_right - x2; ...).
  pure real(wp) function offset_sign(k)
    integer, intent(in) :: k
    real(wp), parameter :: signs(n_limits) = [-1.0_wp, 1.0_wp, -1.0_wp, 1.0_wp]
    offset_sign = signs(k)
  end function offset_sign
end module impact1d_scene

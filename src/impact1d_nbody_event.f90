!> The event point of the N-body engine (METHOD.md 5-6; docs/method.md section 9): closed
!> rows snapped, impacts resolved (one joint inelastic impact of the closed rows when all
!> are plastic, otherwise sequential impulses on the most approaching row), bounce series
!> whose rest is below the clock's resolution put to rest (Zeno), stopped bodies zeroed, the
!> new mode (impact1d_body_mode) and the log of what changed, on N-long arrays and the rows'
!> ends (the two-body engine's rules, whose event point, impact1d_event_point, is gone).
module impact1d_nbody_event
  use impact1d_kinds, only: wp, eps_wp
  use impact1d_error, only: error_type, raise, status_simulation, fmt
  use impact1d_scene, only: scene_type, tutorial_bodies
  use impact1d_state, only: state_type, add_compensated, product_error
  use impact1d_output, only: sink_type, run_stats, class_impact, class_rest, class_stick, class_slip, class_release, &
    class_pair_stick, class_pair_slip
  use impact1d_yardsticks, only: gap_rounding, velocity_rounding, time_rounding, energy_rounding, same_instant, &
    force_scale
  use impact1d_event_log, only: event_log_type, log_event
  use impact1d_friction_laws, only: slip, belt_speed, belt_moving, belt_rate, shift_to_belts, belt_accelerations
  use impact1d_clusters, only: uf_join, uf_find, cluster_set_type, clusters_build
  use impact1d_accumulation, only: join_cycle
  use impact1d_cluster_impact, only: impact_work_type, impact_reserve, cluster_projection
  use impact1d_path_impact, only: path_impact_reserve, path_projection
  use impact1d_lcp, only: lcp_solved, lcp_too_large
  use impact1d_body_mode, only: body_mode_type, mode_work_type, solve_body_mode, mode_solved, max_dense_unknowns, &
    drive_accelerations, shift_to_drives, drive_components, solve_cluster
  use impact1d_nbody_step, only: nbody_force, nbody_rate, row_gap, row_velocity, row_gap_tolerance, &
    found_row, found_body, found_stop, mode_acceleration, ground_motion, stop_gap_band, stop_force_band, &
    found_friction
  implicit none
  private
  public :: point_work_type, new_point_work, nbody_event_point, bounce_series_time

  !> The event point's memory (sized by the run) and what one event point leaves for the
  !> next at the same instant.
  type :: point_work_type
    type(mode_work_type) :: mode
    !> (allocated by the first joint impact of a closed group: a run that has none, a short
    !> call's, does not copy its default-initialised 4.7 kB in and out)
    type(impact_work_type), allocatable :: impact
    !> The last event point's instant and the velocity scale its impulses came from (N).
    real(wp) :: scale_time = -huge(1.0_wp)
    real(wp), allocatable :: scale(:)
    integer, allocatable :: rigid(:)          !< (0:N) bodies locked by rigid links (union-find)
    real(wp), allocatable :: rigid_mass(:)    !< (0:N) mass of each rigid group, by root
    !> The rows on each body (impact1d_clusters' incidence lists, built at the first event
    !> point) and its breadth-first search's queue and marks: what an event touches is found
    !> from its rows' ends, not by a scan of all N (issue 20 item 3).
    type(cluster_set_type) :: incidence
    !> The closed rows of this event point, in row order (list_closed): the loops over closed
    !> rows go over these, not over all rows.
    integer, allocatable :: closed_rows(:)
    integer :: n_closed = 0
    !> Some row is a rigid link's (row_partner): without, every body is its own rigid group.
    logical :: any_rigid = .false.
    integer, allocatable :: local(:)          !< (0:N) joint_projection's body numbering, 0 between uses
    !> No body has friction: a mode is the clusters' solves, every other body alone
    !> (scoped_mode).
    logical :: frictionless = .false.
    !> The bodies and rows of the clusters scoped_mode solved last: the only mode entries
    !> not those of a body alone (when tracked; a solve of all clusters forgets them).
    integer, allocatable :: mode_bodies(:), mode_rows(:)
    integer :: n_mode_bodies = 0, n_mode_rows = 0
    logical :: mode_tracked = .false.
    !> A mode whose entries only the bodies of the clusters solved last are read from
    !> (cluster_acceleration).
    type(body_mode_type) :: scratch
  end type point_work_type

  !> The largest cluster (bodies; rows four times as many) whose mode is solved on its own
  !> to find a row's free gap acceleration; a larger one takes the solve of all clusters.
  integer, parameter :: max_scope = 64, max_scope_rows = 4 * max_scope

contains

  !> The event point's memory for n bodies.
  subroutine new_point_work(n, work)
    integer, intent(in) :: n
    type(point_work_type), intent(inout) :: work
    allocate(work%scale(n), work%rigid(0:n), work%rigid_mass(0:n))
    work%scale = 0.0_wp
  end subroutine new_point_work

  !> What the event points of a run share, set at its first: the rows on each body, the
  !> rigid groups when there are no rigid links (each body alone); the scratch mode at its
  !> first use (scratch_mode).
  subroutine first_point(scene, mode, work)
    type(scene_type), intent(in) :: scene
    type(body_mode_type), intent(in) :: mode
    type(point_work_type), intent(inout) :: work
    integer :: i
    ! (an earlier run's scratch made anew at its first use: scratch_mode)
    if (allocated(work%scratch%stuck)) deallocate(work%scratch%stuck)
    ! (the rigid rows only: the compliant stops' rows after them are elements, never closed)
    call clusters_build(work%incidence, scene%n_bodies, scene%row_body(:, 1:scene%n_rows))
    if (allocated(work%closed_rows)) deallocate(work%closed_rows, work%local)
    allocate(work%closed_rows(max(scene%n_rows, 1)), work%local(0:scene%n_bodies))
    work%local = 0
    work%any_rigid = any(scene%row_partner > 0)
    work%frictionless = all(scene%body_static == 0.0_wp) .and. all(scene%body_friction == 0.0_wp) .and. &
      scene%n_frictions == 0
    if (allocated(work%mode_bodies)) deallocate(work%mode_bodies, work%mode_rows)
    allocate(work%mode_bodies(scene%n_bodies), work%mode_rows(max(scene%n_rows, 1)))
    work%mode_tracked = .false.
    ! (lock_rigid's groups and masses without rigid links)
    work%rigid = [(i, i = 0, scene%n_bodies)]
    work%rigid_mass(0) = 0.0_wp
    work%rigid_mass(1:) = scene%body_mass
  end subroutine first_point

  !> The event point at s%t: found, index say what the location found (a row, a body); initial:
  !> the run's start (no mode yet). Leaves the new mode.
  subroutine nbody_event_point(scene, initial, found, index, s, mode, event_log, work, sink, stats, error)
    type(scene_type), intent(in) :: scene
    logical, intent(in) :: initial
    integer, intent(in) :: found, index
    type(state_type), intent(inout) :: s
    type(body_mode_type), intent(inout) :: mode
    type(event_log_type), intent(inout) :: event_log
    type(point_work_type), intent(inout) :: work
    class(sink_type), intent(inout) :: sink
    type(run_stats), intent(inout) :: stats
    type(error_type), allocatable, intent(inout) :: error
    real(wp), dimension(scene%n_bodies) :: f, df, acc, entry_scale
    logical :: closed(scene%n_rows), candidate(scene%n_rows), hit(scene%n_rows), stopped(scene%n_bodies)
    logical :: pair_was_stuck(scene%n_frictions)
    integer :: k, i, p, status

    if (initial) call first_point(scene, mode, work)
    if (scene%n_stops > 0) then
      call nbody_force(scene, s%t, s%x, s%x_lo, s%v, f, mode%engaged)
      if (initial) then
        acc = f / scene%body_mass
      else
        call mode_acceleration(scene, mode, s%t, f, acc)
      end if
      call switch_stops(scene, found, index, s, acc, mode%engaged, sink, stats)
    end if
    call nbody_force(scene, s%t, s%x, s%x_lo, s%v, f, mode%engaged)
    call nbody_rate(scene, s%t, s%v, df, mode%engaged)
    call close_rows(scene, initial, merge(index, 0, found == found_row), mode%active, s, closed, work%closed_rows, &
      work%n_closed)
    ! Velocity scale of each body entering this event point: impulses redistribute velocity
    ! but cannot create precision, so what is below its rounding is zero.
    if (initial) then
      acc = f / scene%body_mass
    else
      call mode_acceleration(scene, mode, s%t, f, acc)
    end if
    entry_scale = abs(s%v) + abs(acc) * scene%dt
    if (scene%belt_moves) call belt_scale(scene, s%t, entry_scale)
    if (same_instant(scene, s%t, work%scale_time)) entry_scale = max(entry_scale, work%scale)
    do i = 1, scene%n_bodies
      stopped(i) = scene%body_static(i) > 0.0_wp .and. slip(scene, i, s%v(i), s%t) /= 0.0_wp .and. ((found == &
        found_body .and. index == i) .or. abs(slip(scene, i, s%v(i), s%t)) <= velocity_rounding * abs(acc(i)) * scene%dt)
      if (.not. initial) stopped(i) = stopped(i) .and. .not. rides_drive(scene, mode, i, s%t)
      if (stopped(i)) call zero_velocity(scene, s, i)
    end do
    if (scene%n_frictions > 0 .and. .not. initial .and. any(stopped)) call carry_stopped(scene, mode, stopped, s)
    if (found == found_friction) call relative_rest(scene, mode, index, s)
    call lock_rigid(scene, closed, stopped, s, work, sink, stats)
    call impacts(scene, closed, entry_scale, acc, s, work, hit, sink, stats, error)
    if (allocated(error)) return
    if (any(hit)) call cut_cycle(scene, hit, closed, s, event_log, work, sink, stats)
    work%scale_time = s%t
    work%scale = entry_scale
    call settle(scene, mode, closed, f, df, acc, entry_scale, s, event_log, work, sink, stats)

    ! Dampers pull with the velocities the impacts left.
    if (scene%springs%present) then
      call nbody_force(scene, s%t, s%x, s%x_lo, s%v, f, mode%engaged)
      call nbody_rate(scene, s%t, s%v, df, mode%engaged)
    end if
    candidate = .false.
    do p = 1, work%n_closed
      k = work%closed_rows(p)
      candidate(k) = abs(row_velocity(scene, k, s%v, s%t)) <= u_tolerance(scene, k, s%v, acc, entry_scale)
    end do
    ! (solved in place: the old mode is not read past here but for its friction contacts'
    ! stuck flags, kept for the log; a failed solve ends the run)
    if (scene%n_frictions > 0 .and. .not. initial) pair_was_stuck = mode%friction_stuck
    ! (geared groups' scaled accelerations are set_groups' alone: no scoped shortcut)
    if (initial .or. .not. work%frictionless .or. scene%drives%n > 0 .or. scene%geared) then
      call solve_mode_at(scene, work%mode, s%t, f, df, s%v, candidate, mode, status)
      work%mode_tracked = .false.
    else
      call scoped_mode(scene, work, closed, f, df, acc, entry_scale, s%t, s%v, candidate, mode, status)
    end if
    if (status == lcp_too_large) then
      call raise(error, status_simulation, 'at t = ' // trim(fmt(s%t)) // ': the bodies joined by closed ' // &
        'contacts form a cluster too large for the dense mode solve (more than ' // &
        trim(fmt(max_dense_unknowns)) // ' unknowns: some 5000 bodies in contact, their contacts not ' // &
        'a path, such as rigid links with two closed limits)')
      return
    else if (status /= mode_solved) then
      call raise(error, status_simulation, 'at t = ' // trim(fmt(s%t)) // &
        ': no consistent contact and friction state (complementarity problem has no solution)')
      return
    end if
    if (scene%belt_moves) call refuse_held_belts(scene, mode, s, error)
    if (allocated(error)) return
    if (scene%belt_moves) call still_on_belts(scene, mode, s)
    call log_mode_change(scene, initial, f, df, candidate, mode, s, event_log, sink, stats)
    if (scene%n_frictions > 0 .and. .not. initial) call log_pairs(scene, pair_was_stuck, mode, s, sink, stats)
  end subroutine nbody_event_point

  !> The compliant stops at this instant (docs/method.md section 10): an open stop whose gap
  !> has closed (located, or within its rounding) engages when its ends approach, logged as
  !> an impact on its row (no velocity changes); an engaged one releases when its force
  !> F = -(k gap + c gap') has fallen to zero (located, or within rounding), logged as
  !> release_<row>; one released inside (gap < 0) engages again when F has risen to zero.
  !> acc: the accelerations in the mode so far (a stop at its limit with its ends at rest
  !> relative to each other engages when they accelerate into it).
  subroutine switch_stops(scene, found, index, s, acc, engaged, sink, stats)
    type(scene_type), intent(in) :: scene
    integer, intent(in) :: found, index
    type(state_type), intent(in) :: s
    real(wp), intent(in) :: acc(:)
    logical, intent(inout) :: engaged(:)
    class(sink_type), intent(inout) :: sink
    type(run_stats), intent(inout) :: stats
    real(wp) :: g, u, force, tol, speed
    integer :: j, r
    logical :: located, engage
    do j = 1, scene%n_stops
      r = scene%n_rows + j
      g = row_gap(scene, r, s)
      u = row_velocity(scene, r, s%v, s%t)
      force = -(scene%row_k(r) * g + scene%row_c(r) * u)
      tol = stop_force_band(scene, r, s)
      located = (found == found_row .or. found == found_stop) .and. index == r
      ! A located crossing switches where the force is zero within rounding (refine's
      ! Newton may stop short of it: the next step finds it again); one the location missed
      ! switches where the force is past zero.
      if (engaged(j)) then
        if (force < -tol .or. (located .and. force <= tol)) then
          engaged(j) = .false.
          call log_event(scene, sink, stats, s%t, class_release, r, s%v, s%v)
        end if
        cycle
      end if
      if (g > stop_gap_band(scene, r, s)) cycle
      ! At the limit (gap within rounding) the stop engages when its ends approach (relative
      ! to a moving ground end), or, at rest relative to each other (a body set down on a
      ! compliant floor), accelerate into it (else the gap closing is located at once again
      ! and again); inside it, when its force has risen to zero.
      if (g >= -stop_gap_band(scene, r, s)) then
        speed = maxval(abs(s%v))
        if (scene%drives%n > 0) speed = max(speed, abs(ground_motion(scene, r, s%t, 1)))
        engage = u < -velocity_rounding * speed .or. (u <= velocity_rounding * speed .and. &
          row_velocity(scene, r, acc) + ground_motion(scene, r, s%t, 2) < 0.0_wp)
      else
        engage = force > tol .or. (located .and. force >= -tol)
      end if
      if (engage) then
        engaged(j) = .true.
        call log_event(scene, sink, stats, s%t, class_impact, r, s%v, s%v)
      end if
    end do
  end subroutine switch_stops

  !> solve_body_mode at time t: with moving grounds, on the forces as seen from the ground
  !> the candidate rows hold each body to (impact1d_body_mode's shift_to_drives); a body at
  !> rest on an accelerating belt, as seen from its belt (impact1d_friction_laws'
  !> shift_to_belts).
  subroutine solve_mode_at(scene, work, t, f, df, v, candidate, mode, status)
    type(scene_type), intent(in) :: scene
    type(mode_work_type), intent(inout) :: work
    real(wp), intent(in) :: t, f(:), df(:), v(:)
    logical, intent(in) :: candidate(:)
    type(body_mode_type), intent(inout) :: mode
    integer, intent(out) :: status
    real(wp), dimension(scene%n_bodies) :: f_seen, df_seen
    if (scene%drives%n == 0 .and. .not. scene%belt_moves) then
      call solve_body_mode(scene, work, f, df, v, t, candidate, mode, status)
      return
    end if
    f_seen = f
    df_seen = df
    if (scene%drives%n > 0) call shift_to_drives(scene, t, candidate, f_seen, df_seen)
    if (scene%belt_moves) call shift_to_belts(scene, t, v, f_seen, df_seen)
    call solve_body_mode(scene, work, f_seen, df_seen, v, t, candidate, mode, status)
  end subroutine solve_mode_at

  !> A body stuck on a belt of sine speed may not be an end of a held row, but for a row
  !> between two bodies stuck on belts of the same acceleration: the mode solve takes such
  !> rows (impact1d_body_mode's gather_belt_frames), but a body held against a stuck one
  !> would ride its belt, which the groups' motion (group 0 still but for each stuck body's
  !> own belt) does not take yet: the run ends there, naming the body and the row. A row
  !> that the belt carries its body away from, or a body that slides on its belt against a
  !> wall or a neighbour, runs.
  subroutine refuse_held_belts(scene, mode, s, error)
    type(scene_type), intent(in) :: scene
    type(body_mode_type), intent(in) :: mode
    type(state_type), intent(in) :: s
    type(error_type), allocatable, intent(inout) :: error
    integer :: k, e, i
    do k = 1, scene%n_rows
      if (.not. mode%active(k)) cycle
      if (same_belt_frame(k)) cycle
      do e = 1, 2
        i = scene%row_body(e, k)
        if (i == 0) cycle
        if (.not. (mode%stuck(i) .and. belt_moving(scene, i))) cycle
        call raise(error, status_simulation, 'at t = ' // trim(fmt(s%t)) // ': body ' // trim(fmt(i)) // &
          ', stuck on its belt of sine speed (belt_amp), holds the contact ' // trim(scene%row_name(k)) // &
          ' closed: a body held against one stuck on such a belt cannot ride it yet (docs/method.md section 12)')
        return
      end do
    end do

  contains

    !> Row k joins two stuck bodies whose belts accelerate alike (their row's n.b and its
    !> rate zero: each rides its own belt, the row stays closed).
    logical function same_belt_frame(k)
      integer, intent(in) :: k
      integer :: a, b
      a = scene%row_body(1, k)
      b = scene%row_body(2, k)
      same_belt_frame = .false.
      if (a == 0) return
      if (.not. (mode%stuck(a) .and. mode%stuck(b))) return
      same_belt_frame = scene%row_normal(1, k) * belt_rate(scene, a, s%t, 2) + &
        scene%row_normal(2, k) * belt_rate(scene, b, s%t, 2) == 0.0_wp .and. &
        scene%row_normal(1, k) * belt_rate(scene, a, s%t, 3) + scene%row_normal(2, k) * belt_rate(scene, b, s%t, 3) &
        == 0.0_wp
    end function same_belt_frame
  end subroutine refuse_held_belts

  !> A body on a belt of sine speed that the mode holds still (against a wall) and slides:
  !> its velocity exactly 0, not its belt's speed within rounding of 0 where it stopped on
  !> its belt (else it creeps off the wall by that rounding); the rounding's energy is
  !> friction's, as zero_velocity books it.
  pure subroutine still_on_belts(scene, mode, s)
    type(scene_type), intent(in) :: scene
    type(body_mode_type), intent(in) :: mode
    type(state_type), intent(inout) :: s
    integer :: i
    do i = 1, scene%n_bodies
      if (mode%group(i) /= 0 .or. mode%stuck(i) .or. s%v(i) == 0.0_wp) cycle
      if (mode%drive(i) /= 0 .or. .not. belt_moving(scene, i)) cycle
      call add_compensated(s%friction_loss, s%friction_lo, 0.5_wp * scene%body_mass(i) * s%v(i)**2)
      s%v(i) = 0.0_wp
      s%v_lo(i) = 0.0_wp
    end do
  end subroutine still_on_belts

  !> A body on a belt of sine speed has the belt's velocity scale too, that of V's terms
  !> (|belt_v| + |belt_amp|, its rounding's) and of a step's change |V'| dt: held still
  !> against a wall while it slides, it stops on its belt where the belt's speed is within
  !> rounding of 0, not at 0 (a rounding of approach, no impact).
  pure subroutine belt_scale(scene, t, scale)
    type(scene_type), intent(in) :: scene
    real(wp), intent(in) :: t
    real(wp), intent(inout) :: scale(:)
    integer :: i
    do i = 1, scene%n_bodies
      if (belt_moving(scene, i)) scale(i) = scale(i) + abs(scene%body_belt(i)) + abs(scene%body_belt_amp(i)) + &
        abs(belt_rate(scene, i, t, 2)) * scene%dt
    end do
  end subroutine belt_scale

  !> The closed rows (the located one, gaps within rounding; at the start, within the
  !> rounding of the user's decimals; in a geared scene with friction the rows the mode
  !> held), a rigid link's two rows together, each snapped onto its constraint.
  pure subroutine close_rows(scene, initial, located, held, s, closed, rows, n_closed)
    type(scene_type), intent(in) :: scene
    logical, intent(in) :: initial
    integer, intent(in) :: located
    logical, intent(in) :: held(:)      !< the rows the mode held up to here
    type(state_type), intent(inout) :: s
    logical, intent(out) :: closed(:)
    integer, intent(out) :: rows(:), n_closed    !< the closed rows in row order
    integer :: k
    real(wp) :: size_scale
    logical :: keep_held
    keep_held = scene%geared .and. .not. initial
    if (keep_held) keep_held = any(scene%body_static > 0.0_wp)
    do k = 1, scene%n_rows
      closed(k) = k == located .or. row_gap(scene, k, s) <= row_gap_tolerance(scene, k, s, 0.0_wp)
      if (initial .and. .not. closed(k)) then
        size_scale = max(abs(s%x(scene%row_body(2, k))), abs(scene%row_offset(k)))
        if (scene%row_body(1, k) > 0) size_scale = max(size_scale, abs(s%x(scene%row_body(1, k))))
        closed(k) = row_gap(scene, k, s) <= gap_rounding * size_scale
      end if
      ! A held geared row's ends move at s_b V and s_a V, each rounded: its gap drifts from
      ! the limit by that rounding, beyond the low parts' (a unit row's ends move alike), and
      ! would open a mesh that a geared group pressed at a stop. (With friction only: without
      ! it the same rule merges input/geared_train.nml's mesh1 impact one ulp after mesh2's
      ! into mesh2's event point, which moves its golden bits; docs/method.md section 14.)
      if (keep_held) closed(k) = closed(k) .or. held(k)
    end do
    do k = 1, scene%n_rows
      if (scene%row_partner(k) > 0) closed(k) = closed(k) .or. closed(scene%row_partner(k))
    end do
    call list_closed(closed, rows, n_closed)
    call snap_closed(scene, rows(:n_closed), s)
  end subroutine close_rows

  !> The rows marked closed, in row order.
  pure subroutine list_closed(closed, rows, n_closed)
    logical, intent(in) :: closed(:)
    integer, intent(out) :: rows(:), n_closed
    integer :: k
    n_closed = 0
    do k = 1, size(closed)
      if (.not. closed(k)) cycle
      n_closed = n_closed + 1
      rows(n_closed) = k
    end do
  end subroutine list_closed

  !> Put every closed row exactly on its constraint, the bodies placed outward from what
  !> holds them: the bodies on closed ground rows first (at -offset / n_b), then across
  !> closed rows from a placed end to the other, so that a chain held at either end (bodies
  !> pressed between a wall and a row, in any record order) is put on all its constraints at
  !> once; snapping row by row, a later row moved a body an earlier one had placed, leaving
  !> that row's gap at a rounding-level negative value that the location found again at once,
  !> event point after event point. A group on no closed ground row starts from the a end of
  !> its first closed row. Rows whose ends are both placed already (a closed loop, a rigid
  !> link's second limit) move nothing. Passes alternate in direction: a chain takes two.
  pure subroutine snap_closed(scene, closed, s)
    type(scene_type), intent(in) :: scene
    integer, intent(in) :: closed(:)      !< the closed rows, in row order
    type(state_type), intent(inout) :: s
    logical :: placed(0:scene%n_bodies), grew
    real(wp) :: limit
    integer :: k, j, p, first, last, step
    placed = .false.
    do p = 1, size(closed)
      k = closed(p)
      if (scene%row_body(1, k) /= 0) cycle
      associate (b => scene%row_body(2, k))
        s%x(b) = -scene%row_offset(k) / scene%row_normal(2, k)
        s%x_lo(b) = 0.0_wp
        ! (a moving ground's w(t) added exactly, to the clock's low part: row_gap's)
        if (scene%drives%n > 0) call place_on_drive(k, b, s)
        placed(b) = .true.
      end associate
    end do
    step = -1
    do
      grew = .false.
      step = -step
      first = merge(1, size(closed), step > 0)
      last = merge(size(closed), 1, step > 0)
      do p = first, last, step
        k = closed(p)
        if (scene%row_body(1, k) == 0) cycle
        associate (ea => scene%row_body(1, k), eb => scene%row_body(2, k))
          if (placed(ea) .eqv. placed(eb)) cycle
          limit = -scene%row_offset(k) / scene%row_normal(2, k)
          if (scene%geared) then
            ! (a geared row, x_b - n x_a = limit)
            if (abs(scene%row_normal(1, k)) /= 1.0_wp) then
              call place_geared(ea, eb, abs(scene%row_normal(1, k)), limit, placed(ea), s)
              placed(ea) = .true.
              placed(eb) = .true.
              grew = .true.
              cycle
            end if
          end if
          if (placed(ea)) then
            s%x(eb) = s%x(ea)
            s%x_lo(eb) = s%x_lo(ea)
            call add_compensated(s%x(eb), s%x_lo(eb), limit)
          else
            s%x(ea) = s%x(eb)
            s%x_lo(ea) = s%x_lo(eb)
            call add_compensated(s%x(ea), s%x_lo(ea), -limit)
          end if
          ! (each end by itself: a vector subscript took a heap temporary a row)
          placed(ea) = .true.
          placed(eb) = .true.
          grew = .true.
        end associate
      end do
      if (grew) cycle
      ! A group that no placed body reaches: its first row's a end stays where it is.
      do p = 1, size(closed)
        j = closed(p)
        if (scene%row_body(1, j) == 0) cycle
        if (.not. (placed(scene%row_body(1, j)) .or. placed(scene%row_body(2, j)))) exit
      end do
      if (p > size(closed)) exit
      placed(scene%row_body(1, j)) = .true.
      step = -1
    end do

  contains

    !> A geared row's ends on x_b - n x_a = limit, b placed from a (from_a) or a from b,
    !> the products' rounding errors kept in the low parts (impact1d_state's product_error).
    pure subroutine place_geared(a, b, n, limit, from_a, s)
      integer, intent(in) :: a, b
      real(wp), intent(in) :: n, limit
      logical, intent(in) :: from_a
      type(state_type), intent(inout) :: s
      real(wp) :: y, y_lo
      if (from_a) then
        s%x(b) = n * s%x(a)
        s%x_lo(b) = n * s%x_lo(a) + product_error(n, s%x(a))
        call add_compensated(s%x(b), s%x_lo(b), limit)
      else
        y = s%x(b)
        y_lo = s%x_lo(b)
        call add_compensated(y, y_lo, -limit)
        s%x(a) = y / n
        ! (y - n x_a is exact: the two are within a rounding of each other)
        s%x_lo(a) = (((y - n * s%x(a)) - product_error(n, s%x(a))) + y_lo) / n
      end if
    end subroutine place_geared

    !> Body b on row k's ground end: w(t + t_lo) as its two parts (impact1d_drives'
    !> position_parts).
    pure subroutine place_on_drive(k, b, s)
      integer, intent(in) :: k, b
      type(state_type), intent(inout) :: s
      real(wp) :: w, w_lo
      if (scene%row_drive(k) == 0) return
      call scene%drives%position_parts(scene%row_drive(k), s%t, s%t_lo, w, w_lo)
      call add_compensated(s%x(b), s%x_lo(b), w)
      call add_compensated(s%x(b), s%x_lo(b), w_lo)
    end subroutine place_on_drive
  end subroutine snap_closed

  !> Bodies joined by rigid links whose two rows are closed (d_min = d_max) are one body: the
  !> groups (work%rigid, 0 the ground for a link to it) and their masses; each group moves
  !> with its centre of mass (a relative velocity the link cannot have is absorbed, as by a
  !> plastic impact, booked as impact loss and logged as an impact of the link's row that
  !> approached, as tests/exact_nbody.py logs it). stopped: the
  !> bodies friction has just stopped (their rounding-level speed zeroed); the groups they
  !> move with stop with them, silently: the speed the others kept was that rounding.
  subroutine lock_rigid(scene, closed, stopped, s, work, sink, stats)
    type(scene_type), intent(in) :: scene
    logical, intent(in) :: closed(:), stopped(:)
    type(state_type), intent(inout) :: s
    type(point_work_type), intent(inout) :: work
    class(sink_type), intent(inout) :: sink
    type(run_stats), intent(inout) :: stats
    real(wp) :: momentum(0:scene%n_bodies), v_new(scene%n_bodies), v_before(scene%n_bodies), frame(scene%n_bodies)
    integer :: i, k, r
    logical :: joined, halt(0:scene%n_bodies), links(scene%n_rows)
    type(error_type), allocatable :: ignored
    if (.not. work%any_rigid) then
      ! No rigid links: each body its own group (first_point's), the stopped ones halt alone.
      do i = 1, scene%n_bodies
        if (stopped(i)) call zero_velocity(scene, s, i)
      end do
      return
    end if
    work%rigid = [(i, i = 0, scene%n_bodies)]
    do k = 1, scene%n_rows
      if (scene%row_partner(k) == 0) cycle
      if (closed(k) .and. closed(scene%row_partner(k))) joined = uf_join(work%rigid, scene%row_body(1, k), &
        scene%row_body(2, k))
    end do
    halt = .false.
    do i = 1, scene%n_bodies
      if (stopped(i)) halt(uf_find(work%rigid, i)) = .true.
    end do
    do i = 1, scene%n_bodies
      if (halt(uf_find(work%rigid, i))) call zero_velocity(scene, s, i)
    end do
    work%rigid_mass = 0.0_wp
    momentum = 0.0_wp
    do i = 1, scene%n_bodies
      r = uf_find(work%rigid, i)
      work%rigid_mass(r) = work%rigid_mass(r) + scene%body_mass(i)
      momentum(r) = momentum(r) + scene%body_mass(i) * s%v(i)
    end do
    v_new = s%v
    ! (a group linked rigidly to a moving ground moves with it: the links' frame)
    if (scene%drives%n > 0) then
      do k = 1, scene%n_rows
        links(k) = scene%row_partner(k) > 0 .and. closed(k)
        if (links(k)) links(k) = closed(scene%row_partner(k))
      end do
      frame = frame_velocity(scene, links, s%t)
    end if
    do i = 1, scene%n_bodies
      r = work%rigid(i)
      if (r == 0) then
        v_new(i) = 0.0_wp
        if (scene%drives%n > 0) v_new(i) = frame(i)
      else if (work%rigid_mass(r) /= scene%body_mass(i)) then
        v_new(i) = momentum(r) / work%rigid_mass(r)
      end if
    end do
    if (all(v_new == s%v)) return
    v_before = s%v
    if (scene%drives%n > 0) then
      call apply_driven(scene, links, s, v_new, ignored)
    else
      call apply(scene, s, v_new)
    end if
    do k = 1, scene%n_rows
      if (scene%row_partner(k) == 0) cycle
      if (.not. (closed(k) .and. closed(scene%row_partner(k)))) cycle
      if (row_velocity(scene, k, v_before, s%t) < -u_tolerance(scene, k, v_before, spread(0.0_wp, 1, scene%n_bodies), &
          spread(0.0_wp, 1, scene%n_bodies))) call log_event(scene, sink, stats, s%t, class_impact, k, v_before, s%v)
    end do
  end subroutine lock_rigid

  !> Rounding level of row k's normal velocity: from the speeds of its ends and what a step
  !> changes them by, not below the speeds they entered the event point with.
  pure real(wp) function u_tolerance(scene, k, v, acc, entry_scale) result(tol)
    type(scene_type), intent(in) :: scene
    integer, intent(in) :: k
    real(wp), intent(in) :: v(:), acc(:), entry_scale(:)
    integer :: e, i
    tol = 0.0_wp
    do e = 1, 2
      i = scene%row_body(e, k)
      ! (|n_e| = 1 but on a geared row's a end)
      if (i > 0) tol = tol + abs(scene%row_normal(e, k)) * max(abs(v(i)) + abs(acc(i)) * scene%dt, &
        entry_scale(i))
    end do
    tol = velocity_rounding * tol
  end function u_tolerance

  !> The impacts at this instant (the reference's rule, tests/exact_nbody.py): while a closed
  !> row approaches beyond its tolerance, the fastest one and the closed rows joined to it
  !> through shared bodies (its group) take one joint inelastic impact when the group has
  !> several rows, all plastic (a rigid link's own rows count as plastic) and not just one
  !> rigid link; otherwise that row alone takes Newton's impulse through the rigid groups'
  !> masses. A plastic impact leaves its rows' normal velocities exactly 0 (the bodies they
  !> join move as one). hit: the rows that took an impulse.
  subroutine impacts(scene, closed, entry_scale, acc, s, work, hit, sink, stats, error)
    type(scene_type), intent(in) :: scene
    logical, intent(in) :: closed(:)
    real(wp), intent(inout) :: entry_scale(:)
    real(wp), intent(in) :: acc(:)
    type(state_type), intent(inout) :: s
    type(point_work_type), intent(inout) :: work
    logical, intent(out) :: hit(:)
    class(sink_type), intent(inout) :: sink
    type(run_stats), intent(inout) :: stats
    type(error_type), allocatable, intent(inout) :: error
    real(wp), dimension(scene%n_bodies) :: v_before, v_after
    real(wp) :: restitution(scene%n_rows), tol(scene%n_rows)
    logical :: pushed(scene%n_rows), group(scene%n_rows), internal(scene%n_rows), joint
    integer :: k, p, n_impulses, root_a, root_b, group_rows(scene%n_rows), n_group

    hit = .false.
    internal = .false.
    tol = 0.0_wp
    ! (only closed rows' restitution is read; with rigid links every row's roots are found,
    ! as they were: the union-find's path halving is part of what impulse reads)
    do p = 1, merge(scene%n_rows, work%n_closed, work%any_rigid)
      k = p
      if (.not. work%any_rigid) k = work%closed_rows(p)
      root_a = uf_find(work%rigid, scene%row_body(1, k))
      root_b = uf_find(work%rigid, scene%row_body(2, k))
      internal(k) = closed(k) .and. root_a == root_b
      restitution(k) = merge(0.0_wp, scene%row_restitution(k), internal(k))
    end do
    n_impulses = 0
    do
      call closed_tolerances(tol)
      k = most_approaching(scene, work%closed_rows(:work%n_closed), s%t, s%v, tol)
      if (k == 0) exit
      n_impulses = n_impulses + 1
      if (n_impulses > scene%max_impulses) then
        call raise(error, status_simulation, 'at t = ' // trim(fmt(s%t)) // ': the impacts did not settle after ' &
          // trim(fmt(scene%max_impulses)) // ' impulses (typically a light body squeezed between much ' // &
          'heavier ones or a wall: the impulses pass back and forth, more of them the larger the mass ' // &
          'ratio; raise &run max_impulses)')
        return
      end if
      call closed_group(scene, work%incidence, closed, k, group, group_rows, n_group)
      joint = n_group > 1 .and. all(restitution(group_rows(:n_group)) == 0.0_wp) .and. &
        .not. all(internal(group_rows(:n_group)))
      v_before = s%v
      if (joint) then
        ! (tol is this iteration's: the velocities have not moved since)
        call joint_projection(scene, work, group, group_rows(:n_group), s%t, s%v, tol, v_after, pushed, error)
        if (allocated(error)) return
      else
        call impulse(scene, work, k, restitution(k), s%t, s%v, v_after)
        pushed = .false.
        pushed(k) = .true.
      end if
      if (joint .or. restitution(k) == 0.0_wp) call join_moving(scene, pushed .or. internal, s%t, v_after)
      if (scene%drives%n > 0) then
        call apply_driven(scene, group, s, v_after, error)
        if (allocated(error)) return
      else
        call check_dissipative(scene, s%t, v_before, v_after, 0.0_wp, error)
        if (allocated(error)) return
        call apply(scene, s, v_after)
      end if
      ! (what was pushed is in the group: its rows, in row order)
      call share_scale(scene, pushed, group_rows(:n_group), entry_scale)
      do p = 1, n_group
        k = group_rows(p)
        hit(k) = hit(k) .or. pushed(k)
        if (pushed(k)) call log_event(scene, sink, stats, s%t, class_impact, k, v_before, s%v)
      end do
    end do

  contains

    !> The closed rows' u_tolerance now (only they are read: most_approaching looks at
    !> closed rows, a joint impact at its group's; every row's was a few percent of a
    !> 1000-body chain's run).
    subroutine closed_tolerances(tol)
      real(wp), intent(inout) :: tol(:)
      integer :: j
      do j = 1, work%n_closed
        tol(work%closed_rows(j)) = u_tolerance(scene, work%closed_rows(j), s%v, acc, entry_scale)
      end do
    end subroutine closed_tolerances
  end subroutine impacts

  !> New velocities from an impact among the closed rows marked (rows) in a scene with moving
  !> grounds: the prescribed motion's work, the momentum each moving ground gave times its
  !> velocity, goes to drive_work, the rest of the change of kinetic energy to impact loss
  !> (which the impact, taken in the ground's frame, cannot make negative).
  subroutine apply_driven(scene, rows, s, v_after, error)
    type(scene_type), intent(in) :: scene
    logical, intent(in) :: rows(:)
    type(state_type), intent(inout) :: s
    real(wp), intent(in) :: v_after(:)
    type(error_type), allocatable, intent(inout) :: error
    real(wp) :: drive
    drive = dot_product(scene%body_mass, (v_after - s%v) * frame_velocity(scene, rows, s%t))
    call check_dissipative(scene, s%t, s%v, v_after, drive, error)
    if (allocated(error)) return
    call apply(scene, s, v_after, drive)
  end subroutine apply_driven

  !> impact1d_accumulation's join_cycle (the bodies the rows marked join move as one, at rest
  !> when joined to the ground) at t: with moving grounds, moving with the ground they are
  !> joined to; geared rows (docs/method.md section 14) join nothing.
  subroutine join_moving(scene, rows, t, v)
    type(scene_type), intent(in) :: scene
    logical, intent(in) :: rows(:)
    real(wp), intent(in) :: t
    real(wp), intent(inout) :: v(:)
    real(wp) :: frame(scene%n_bodies)
    if (scene%geared) then
      call join_unit_rows(scene, rows, v)
      return
    end if
    if (scene%drives%n == 0) then
      call join_cycle(scene%row_body, rows, scene%body_mass, v)
      return
    end if
    frame = frame_velocity(scene, rows, t)
    v = v - frame
    call join_cycle(scene%row_body, rows, scene%body_mass, v)
    v = v + frame
  end subroutine join_moving

  !> join_moving in a geared scene: the rows marked that are walls or of unit ratio join
  !> their ends; a geared row's do not move alike (its impulse left v_b - n v_a at 0 itself).
  !> Apart from join_moving, so that the event point keeps it inlined.
  subroutine join_unit_rows(scene, rows, v)
    type(scene_type), intent(in) :: scene
    logical, intent(in) :: rows(:)
    real(wp), intent(inout) :: v(:)
    call join_cycle(scene%row_body, rows .and. (scene%row_body(1, :scene%n_rows) == 0 .or. &
      abs(scene%row_normal(1, :scene%n_rows)) == 1.0_wp), scene%body_mass, v)
  end subroutine join_unit_rows

  !> Each body's moving ground's velocity at t through the rows marked (0: none).
  pure function frame_velocity(scene, rows, t) result(frame)
    type(scene_type), intent(in) :: scene
    logical, intent(in) :: rows(:)
    real(wp), intent(in) :: t
    real(wp) :: frame(scene%n_bodies)
    integer :: drive(scene%n_bodies), i
    call drive_components(scene, rows, drive)
    frame = 0.0_wp
    do i = 1, scene%n_bodies
      if (drive(i) > 0) frame(i) = scene%drives%velocity(drive(i), t)
    end do
  end function frame_velocity

  !> The closed rows joined to row `start` through shared bodies (the ground joins nothing):
  !> group, and the same rows listed in row order (rows(:n)). Breadth first over the rows on
  !> each body reached (set: the incidence lists), so O(the group), not sweeps over all rows.
  subroutine closed_group(scene, set, closed, start, group, rows, n)
    type(scene_type), intent(in) :: scene
    type(cluster_set_type), intent(inout) :: set
    logical, intent(in) :: closed(:)
    integer, intent(in) :: start
    logical, intent(out) :: group(:)
    integer, intent(out) :: rows(:), n
    integer :: head, n_queued, p, j, e, b
    group = .false.
    group(start) = .true.
    rows(1) = start
    n = 1
    set%stamp = set%stamp + 1
    n_queued = 0
    call reach_ends(start)
    head = 0
    do while (head < n_queued)
      head = head + 1
      b = set%queue(head)
      do p = set%row_start(b), set%row_start(b + 1) - 1
        j = set%row_list(p)
        if (group(j) .or. .not. closed(j)) cycle
        group(j) = .true.
        n = n + 1
        rows(n) = j
        call reach_ends(j)
      end do
    end do
    ! (row order: a few rows sorted, a long group read off the marks)
    if (n <= max_scope) then
      call sort_increasing(rows(:n))
    else
      call list_closed(group, rows, n)
    end if

  contains

    !> Row j's bodies not reached yet join the queue.
    subroutine reach_ends(j)
      integer, intent(in) :: j
      do e = 1, 2
        associate (i => scene%row_body(e, j))
          if (i == 0) cycle
          if (set%mark(i) == set%stamp) cycle
          set%mark(i) = set%stamp
          n_queued = n_queued + 1
          set%queue(n_queued) = i
        end associate
      end do
    end subroutine reach_ends
  end subroutine closed_group

  !> An event point whose impulses hit the rows marked, recorded; when the last points make
  !> an accumulation over several contacts (impact1d_accumulation) whose rest is near, its
  !> rows close now: snapped, the bodies they join moving as one (at rest if joined to the
  !> ground), their rests logged at the series' limit time.
  subroutine cut_cycle(scene, hit, closed, s, event_log, work, sink, stats)
    type(scene_type), intent(in) :: scene
    logical, intent(in) :: hit(:)
    logical, intent(inout) :: closed(:)
    type(state_type), intent(inout) :: s
    type(event_log_type), intent(inout) :: event_log
    type(point_work_type), intent(inout) :: work
    class(sink_type), intent(inout) :: sink
    type(run_stats), intent(inout) :: stats
    real(wp) :: u(scene%n_rows), remaining, v(scene%n_bodies)
    logical :: rows(scene%n_rows), found
    type(error_type), allocatable :: ignored
    integer :: k
    do k = 1, scene%n_rows
      u(k) = row_velocity(scene, k, s%v, s%t)
    end do
    call event_log%cycles%record(s%t, hit, u)
    call event_log%cycles%find_cycle(scene%row_body, scene%dt, time_rounding * max(abs(s%t), scene%dt), rows, remaining, found)
    if (.not. found) return
    call event_log%cycles%forget()
    closed = closed .or. rows
    call list_closed(closed, work%closed_rows, work%n_closed)
    call snap_closed(scene, work%closed_rows(:work%n_closed), s)
    v = s%v
    call join_moving(scene, rows, s%t, v)
    if (scene%drives%n > 0) then
      call apply_driven(scene, rows, s, v, ignored)
    else
      call apply(scene, s, v)
    end if
    do k = 1, scene%n_rows
      if (rows(k)) call event_log%begin_rest(scene, k, s%t, s%t + remaining, s%v, sink, stats)
    end do
  end subroutine cut_cycle

  !> The closed row approaching fastest beyond its tolerance (0 if none; the first in row
  !> order among equals); rows inside a rigid group never approach.
  integer function most_approaching(scene, closed, t, v, tol) result(k_best)
    type(scene_type), intent(in) :: scene
    integer, intent(in) :: closed(:)      !< the closed rows, in row order
    real(wp), intent(in) :: t, v(:), tol(:)
    integer :: k, p
    real(wp) :: u, u_best
    k_best = 0
    u_best = 0.0_wp
    do p = 1, size(closed)
      k = closed(p)
      u = row_velocity(scene, k, v, t)
      if (u < min(u_best, -tol(k))) then
        k_best = k
        u_best = u
      end if
    end do
  end function most_approaching

  !> Velocities after an impulse on row k that leaves its normal velocity at -r times its
  !> value before, through the rigid groups of its ends (a group joined to the ground does
  !> not move, or moves with its moving ground); a row inside one group takes none.
  subroutine impulse(scene, work, k, r, t, v, v_after)
    type(scene_type), intent(in) :: scene
    type(point_work_type), intent(inout) :: work
    integer, intent(in) :: k
    real(wp), intent(in) :: r, t, v(:)
    real(wp), intent(out) :: v_after(:)
    real(wp) :: inverse(2), p
    integer :: e, i, root(2)
    v_after = v
    do e = 1, 2
      root(e) = uf_find(work%rigid, scene%row_body(e, k))
      inverse(e) = 0.0_wp
      if (root(e) > 0) inverse(e) = 1.0_wp / work%rigid_mass(root(e))
    end do
    if (root(1) == root(2) .or. sum(inverse) == 0.0_wp) return
    if (scene%geared) then
      ! (a geared row's normal (-n, 1): its effective mass is 1 / (n^2 / m_a + 1 / m_b))
      p = -(1.0_wp + r) * row_velocity(scene, k, v, t) / sum(inverse * scene%row_normal(:, k)**2)
    else
      p = -(1.0_wp + r) * row_velocity(scene, k, v, t) / sum(inverse)
    end if
    if (.not. work%any_rigid) then
      ! (each body its own group: the row's ends alone)
      do e = 1, 2
        if (root(e) > 0) v_after(root(e)) = v(root(e)) + scene%row_normal(e, k) * p * inverse(e)
      end do
      return
    end if
    do i = 1, scene%n_bodies
      do e = 1, 2
        if (root(e) > 0 .and. work%rigid(i) == root(e)) v_after(i) = v(i) + scene%row_normal(e, k) * p * inverse(e)
      end do
    end do
  end subroutine impulse

  !> The joint perfectly inelastic impact of the closed rows marked (closed; listed in row
  !> order: rows) (impact1d_cluster_impact), on the bodies they touch gathered into one
  !> problem: v_after, and pushed, the rows it pushed. With moving grounds it is taken in
  !> each body's ground's frame (frame_velocity).
  subroutine joint_projection(scene, work, closed, rows, t, v, tol, v_after, pushed, error)
    type(scene_type), intent(in) :: scene
    type(point_work_type), intent(inout) :: work
    logical, intent(in) :: closed(:)
    integer, intent(in) :: rows(:)
    real(wp), intent(in) :: t, v(:), tol(:)
    real(wp), intent(out) :: v_after(:)
    logical, intent(out) :: pushed(:)
    type(error_type), allocatable, intent(inout) :: error
    integer :: body(scene%n_bodies), row_local(2, size(rows)), nb, nr, k, e, status
    real(wp) :: v_local(scene%n_bodies), impulse_local(size(rows)), frame(scene%n_bodies)
    logical :: pushed_local(size(rows)), fits
    nb = 0
    nr = size(rows)
    ! (work%local: 0 but for the bodies numbered here, reset before leaving)
    do k = 1, nr
      do e = 1, 2
        associate (i => scene%row_body(e, rows(k)))
          if (i == 0) cycle
          if (work%local(i) > 0) cycle
          nb = nb + 1
          body(nb) = i
          work%local(i) = nb
        end associate
      end do
    end do
    do k = 1, nr
      row_local(1, k) = work%local(scene%row_body(1, rows(k)))
      row_local(2, k) = work%local(scene%row_body(2, rows(k)))
    end do
    work%local(body(:nb)) = 0
    v_after = v
    pushed = .false.
    if (nr == 0) return
    ! (with moving grounds the projection is taken in their frame: frame_velocity)
    frame = 0.0_wp
    if (scene%drives%n > 0) frame = frame_velocity(scene, closed, t)
    if (.not. allocated(work%impact)) allocate(work%impact)
    call path_impact_reserve(work%impact%path, nb)
    call path_projection(work%impact%path, scene%body_mass(body(:nb)), v(body(:nb)) - frame(body(:nb)), row_local(:, :nr), &
      scene%row_normal(:, rows(:nr)), tol(rows(:nr)), v_local(:nb), impulse_local(:nr), pushed_local(:nr), fits)
    if (.not. fits) then
      call dense_projection()
      if (allocated(error)) return
    end if
    v_after(body(:nb)) = v_local(:nb)
    if (scene%drives%n > 0) v_after(body(:nb)) = v_local(:nb) + frame(body(:nb))
    pushed(rows(:nr)) = pushed_local(:nr)

  contains

    !> Any other group: the dense LCP (impact1d_cluster_impact).
    subroutine dense_projection()
      if (nr > max_dense_unknowns) then
        call raise(error, status_simulation, 'a joint impact of ' // trim(fmt(nr)) // ' closed contacts is ' // &
          'too large for the dense projection (more than ' // trim(fmt(max_dense_unknowns)) // ': issue 20)')
        return
      end if
      call impact_reserve(work%impact, nb, nr)
      call cluster_projection(work%impact, scene%body_mass(body(:nb)), v(body(:nb)) - frame(body(:nb)), row_local(:, :nr), &
        scene%row_normal(:, rows(:nr)), spread(.true., 1, nr), tol(rows(:nr)), v_local(:nb), impulse_local(:nr), &
        pushed_local(:nr), status)
      if (status /= lcp_solved) then
        call raise(error, status_simulation, 'internal: the joint inelastic impact has no solution (LCP status ' // &
          trim(fmt(status)) // '): please report the scene')
        return
      end if
    end subroutine dense_projection
  end subroutine joint_projection

  !> A row between bodies that took an impulse gives both its ends the larger scale.
  pure subroutine share_scale(scene, pushed, rows, entry_scale)
    type(scene_type), intent(in) :: scene
    logical, intent(in) :: pushed(:)
    integer, intent(in) :: rows(:)     !< rows in row order, the pushed ones among them
    real(wp), intent(inout) :: entry_scale(:)
    integer :: k, p
    do p = 1, size(rows)
      k = rows(p)
      if (.not. pushed(k) .or. scene%row_body(1, k) == 0) cycle
      ! (the two ends by name: a vector subscript took a heap temporary a row)
      associate (a => scene%row_body(1, k), b => scene%row_body(2, k))
        entry_scale(a) = max(entry_scale(a), entry_scale(b))
        entry_scale(b) = entry_scale(a)
      end associate
    end do
  end subroutine share_scale

  !> After the impacts: bodies stopped within rounding are at rest, approach left at two or
  !> more closed rows goes jointly, rounding-level normal velocities on closed rows are
  !> zero, bounce series whose remaining time is below the clock's resolution end in rest,
  !> and a body against a stopped one (a closed row, still) stops too.
  subroutine settle(scene, mode, closed, f, df, acc, entry_scale, s, event_log, work, sink, stats)
    type(scene_type), intent(in) :: scene
    type(body_mode_type), intent(in) :: mode
    logical, intent(in) :: closed(:)
    real(wp), intent(in) :: f(:), df(:), acc(:), entry_scale(:)
    type(state_type), intent(inout) :: s
    type(event_log_type), intent(inout) :: event_log
    type(point_work_type), intent(inout) :: work
    class(sink_type), intent(inout) :: sink
    type(run_stats), intent(inout) :: stats
    real(wp) :: v_after(scene%n_bodies)
    logical :: pushed(scene%n_rows)
    type(error_type), allocatable :: ignored
    integer :: k, e, p
    real(wp) :: accel_bound, u
    call zero_stopped(scene, mode, s, acc, entry_scale)
    associate (rows => work%closed_rows(:work%n_closed))
      call joint_projection(scene, work, closed, rows, s%t, s%v, spread(0.0_wp, 1, scene%n_rows), v_after, pushed, &
        ignored)
      if (.not. allocated(ignored) .and. count(pushed(rows)) >= 2) call settle_apply(closed)
    end associate
    ! (the closed rows, in row order: work%closed_rows)
    do p = 1, work%n_closed
      k = work%closed_rows(p)
      if (abs(row_velocity(scene, k, s%v, s%t)) <= u_tolerance(scene, k, s%v, acc, entry_scale) .and. &
          row_velocity(scene, k, s%v, s%t) /= 0.0_wp) then
        call impulse(scene, work, k, 0.0_wp, s%t, s%v, v_after)
        call settle_apply(closed)
      end if
    end do
    ! A bound on any row's gap acceleration in a mode, |n . a| <= 2 (sum |f| + friction) /
    ! least mass, doubled for rounding, friction at most the static bound (none with moving
    ! grounds, whose rows follow w''; nor with rigid links, whose impulses' union-find steps
    ! must all be taken; nor under Stribeck's law, whose viscous part has no bound)
    accel_bound = huge(1.0_wp)
    if (work%n_closed > 0 .and. scene%drives%n == 0 .and. .not. work%any_rigid .and. .not. scene%stribeck .and. &
        .not. scene%geared) &
      accel_bound = 4.0_wp * (sum(abs(f)) + sum(max(scene%body_friction, scene%body_static))) / &
      minval(scene%body_mass)
    do p = 1, work%n_closed
      k = work%closed_rows(p)
      ! (its tests that need no mode first, here: settle_bounce_series' N-long scratch is a
      ! heap allocation a call)
      u = row_velocity(scene, k, s%v, s%t)
      if (u <= u_tolerance(scene, k, s%v, acc, entry_scale)) cycle
      ! The series lasts at least u / |a_up|: one that cannot end within the clock's
      ! resolution needs no mode solved (settle_bounce_series would return).
      if (u > time_rounding * max(abs(s%t), scene%dt) * accel_bound) cycle
      call settle_bounce_series(scene, mode, k, u, f, df, closed, acc, entry_scale, s, event_log, work, sink, stats)
    end do
    call zero_stopped(scene, mode, s, acc, entry_scale)
    do p = 1, work%n_closed
      k = work%closed_rows(p)
      if (scene%row_body(1, k) == 0) cycle
      if (abs(row_velocity(scene, k, s%v)) > u_tolerance(scene, k, s%v, acc, entry_scale)) cycle
      do e = 1, 2
        if (s%v(scene%row_body(e, k)) == rest_velocity(scene, scene%row_body(e, k), s%t) .and. &
          rest_velocity(scene, scene%row_body(e, k), s%t) == rest_velocity(scene, scene%row_body(3 - e, k), s%t)) &
          call zero_velocity(scene, s, scene%row_body(3 - e, k))
      end do
    end do

  contains

    !> s%v := v_after, a rounding-level change (with moving grounds: their work booked).
    subroutine settle_apply(rows)
      logical, intent(in) :: rows(:)
      type(error_type), allocatable :: unchecked
      if (scene%drives%n > 0) then
        call apply_driven(scene, rows, s, v_after, unchecked)
      else
        call apply(scene, s, v_after)
      end if
    end subroutine settle_apply
  end subroutine settle

  !> The bounce series on closed row k, if its ends separate slowly: the gap's acceleration
  !> rising (a_up) and falling back (a_down) from the mode with k left free. If what remains
  !> of the series is below the clock's resolution, the row rests now, logged at the
  !> series' accumulation time.
  subroutine settle_bounce_series(scene, mode, k, u, f, df, closed, acc, entry_scale, s, event_log, work, sink, stats)
    type(scene_type), intent(in) :: scene
    type(body_mode_type), intent(in) :: mode
    integer, intent(in) :: k
    real(wp), intent(in) :: u    !< its normal velocity, separating beyond rounding (settle)
    real(wp), intent(in) :: f(:), df(:), acc(:), entry_scale(:)
    logical, intent(in) :: closed(:)
    type(state_type), intent(inout) :: s
    type(event_log_type), intent(inout) :: event_log
    type(point_work_type), intent(inout) :: work
    class(sink_type), intent(inout) :: sink
    type(run_stats), intent(inout) :: stats
    real(wp) :: a_up, a_down, remaining, v_bounce(scene%n_bodies)
    type(error_type), allocatable :: unchecked
    call scratch_mode(mode, work)
    a_up = free_gap_acceleration(s%v)
    if (a_up >= 0.0_wp) return
    call impulse(scene, work, k, 1.0_wp, s%t, s%v, v_bounce)
    a_down = free_gap_acceleration(v_bounce)
    remaining = bounce_series_time(u, a_up, a_down, scene%row_restitution(k))
    if (remaining > time_rounding * max(abs(s%t), scene%dt)) return
    call impulse(scene, work, k, 0.0_wp, s%t, s%v, v_bounce)
    if (scene%drives%n > 0) then
      call apply_driven(scene, closed, s, v_bounce, unchecked)
    else
      call apply(scene, s, v_bounce)
    end if
    if (remaining < huge(1.0_wp)) then
      call event_log%begin_rest(scene, k, s%t, s%t + remaining, s%v, sink, stats)
    else
      call event_log%begin_rest(scene, k, s%t, s%t, s%v, sink, stats)
    end if

  contains

    !> Row k's gap acceleration with k left free and the other rows as they are, at
    !> velocities v.
    real(wp) function free_gap_acceleration(v) result(a_gap)
      real(wp), intent(in) :: v(:)
      type(body_mode_type) :: free
      logical :: candidate(scene%n_rows), scoped
      real(wp) :: a(scene%n_bodies)
      integer :: j, status
      call scoped_gap_acceleration(scene, work, k, closed, s%t, v, f, df, acc, entry_scale, a_gap, scoped)
      if (scoped) return
      do j = 1, scene%n_rows
        candidate(j) = closed(j) .and. j /= k
        if (candidate(j)) candidate(j) = abs(row_velocity(scene, j, v, s%t)) <= &
          u_tolerance(scene, j, v, acc, entry_scale)
      end do
      free = mode
      call solve_mode_at(scene, work%mode, s%t, f, df, v, candidate, free, status)
      a_gap = 0.0_wp
      if (status /= mode_solved) return
      call mode_acceleration(scene, free, s%t, f, a)
      a_gap = row_velocity(scene, k, a) + ground_motion(scene, k, s%t, 2)
    end function free_gap_acceleration
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

  !> settle_bounce_series' free gap acceleration of row k at velocities v from the clusters
  !> of k's ends alone (scoped), not from the mode solve of all N bodies: the solve is per
  !> cluster and the accelerations per group, each a sum in body order, so these are the
  !> same numbers. Not scoped (the caller solves every cluster): moving grounds, or a
  !> cluster of more than max_scope bodies. A cluster whose solve fails gives 0, as the
  !> solve of all does (which also gives 0 when another cluster fails: one the event point's
  !> own mode solve then fails on).
  subroutine scoped_gap_acceleration(scene, work, k, closed, t, v, f, df, acc, entry_scale, a_gap, scoped)
    type(scene_type), intent(in) :: scene
    type(point_work_type), intent(inout) :: work
    integer, intent(in) :: k
    logical, intent(in) :: closed(:)
    real(wp), intent(in) :: t, v(:), f(:), df(:), acc(:), entry_scale(:)
    real(wp), intent(out) :: a_gap
    logical, intent(out) :: scoped
    real(wp) :: a_end(2)
    integer :: e, status
    a_gap = 0.0_wp
    a_end = 0.0_wp
    ! (friction contacts between bodies join clusters the rows' incidence lists do not see)
    ! (belts of sine speed: the bodies at rest on them are solved in their frames, which
    ! solve_mode_at shifts to, this not)
    scoped = scene%drives%n == 0 .and. scene%n_frictions == 0 .and. .not. scene%geared .and. .not. scene%belt_moves
    if (.not. scoped) return
    do e = 1, 2
      if (scene%row_body(e, k) == 0) cycle
      call cluster_acceleration(scene, work, k, scene%row_body(e, k), closed, t, v, f, df, acc, entry_scale, &
        a_end(e), status, scoped)
      if (.not. scoped .or. status /= mode_solved) return
    end do
    ! (row_velocity's sum, and free_gap_acceleration's ground term, 0 here)
    a_gap = scene%row_normal(2, k) * a_end(2)
    if (scene%row_body(1, k) > 0) a_gap = a_gap + scene%row_normal(1, k) * a_end(1)
    a_gap = a_gap + 0.0_wp
  end subroutine scoped_gap_acceleration

  !> work%scratch (cluster_acceleration's mode) made a copy of mode at the run's first scoped
  !> solve, not at its first event point (seven allocations a short call need not make): its
  !> entries are written before they are read, so any mode of the run's sizes serves.
  subroutine scratch_mode(mode, work)
    type(body_mode_type), intent(in) :: mode
    type(point_work_type), intent(inout) :: work
    if (.not. allocated(work%scratch%stuck)) work%scratch = mode
  end subroutine scratch_mode

  !> Body i's acceleration in the mode of its cluster (the bodies joined to it by candidate
  !> rows: closed, other than row k, normal velocity within rounding at v), the cluster
  !> found breadth first over the rows on its bodies and solved as solve_body_mode solves
  !> it (members in body order, rows in row order, into work%scratch). fits: the cluster has
  !> at most max_scope bodies and max_scope_rows rows.
  subroutine cluster_acceleration(scene, work, k, i, closed, t, v, f, df, acc, entry_scale, a_i, status, fits)
    type(scene_type), intent(in) :: scene
    type(point_work_type), intent(inout) :: work
    integer, intent(in) :: k, i
    logical, intent(in) :: closed(:)
    real(wp), intent(in) :: t, v(:), f(:), df(:), acc(:), entry_scale(:)
    real(wp), intent(out) :: a_i
    integer, intent(out) :: status
    logical, intent(out) :: fits
    integer :: body(max_scope), rows(max_scope_rows), nb, nr, j
    logical :: needs_solve
    a_i = 0.0_wp
    status = mode_solved
    call cluster_of(scene, work%incidence, k, i, closed, t, v, acc, entry_scale, body, nb, rows, nr, fits)
    if (.not. fits) return
    needs_solve = nr > 0
    do j = 1, nb
      associate (b => body(j))
        work%scratch%stuck(b) = .false.
        work%scratch%sgn(b) = 0.0_wp
        if (v(b) /= 0.0_wp .and. scene%body_friction(b) > 0.0_wp) work%scratch%sgn(b) = sign(1.0_wp, v(b))
        if (scene%body_static(b) > 0.0_wp .and. v(b) == 0.0_wp) needs_solve = .true.
      end associate
    end do
    if (needs_solve) then
      work%mode%first(1:2) = [1, nb + 1]
      work%mode%member(1:nb) = body(:nb)
      work%mode%first_row(1:2) = [1, nr + 1]
      work%mode%row(1:nr) = rows(:nr)
      call solve_cluster(scene, work%mode, 1, f, df, v, t, work%scratch, status)
      if (status /= mode_solved) return
    end if
    do j = 1, nb
      associate (b => body(j))
        if (work%scratch%sgn(b) == 0.0_wp .and. v(b) /= 0.0_wp .and. scene%body_static(b) > 0.0_wp) &
          work%scratch%sgn(b) = sign(1.0_wp, v(b))
      end associate
    end do
    a_i = group_acceleration(scene, work%scratch, work%mode%local, body(:nb), rows(:nr), i, f)
  end subroutine cluster_acceleration

  !> Body i's acceleration in mode (its stuck, sgn, active read for the cluster's bodies and
  !> rows): set_groups' groups and acceleration's sums over i's group, in body order. local:
  !> scratch, (0:N).
  real(wp) function group_acceleration(scene, mode, local, body, rows, i, f) result(a_i)
    type(scene_type), intent(in) :: scene
    type(body_mode_type), intent(in) :: mode
    integer, intent(inout) :: local(0:)
    integer, intent(in) :: body(:), rows(:), i
    real(wp), intent(in) :: f(:)
    integer :: root(0:size(body)), j, p, group
    real(wp) :: load, mass
    logical :: joined
    local(0) = 0
    do j = 1, size(body)
      local(body(j)) = j
      root(j) = j
      if (mode%stuck(body(j))) root(j) = 0
    end do
    root(0) = 0
    do p = 1, size(rows)
      if (mode%active(rows(p))) joined = uf_join(root, local(scene%row_body(1, rows(p))), &
        local(scene%row_body(2, rows(p))))
    end do
    a_i = 0.0_wp
    group = uf_find(root, local(i))
    if (group == 0) return
    load = 0.0_wp
    mass = 0.0_wp
    do j = 1, size(body)
      if (uf_find(root, j) /= group) cycle
      mass = mass + scene%body_mass(body(j))
      load = load + (f(body(j)) + (-scene%body_friction(body(j)) * mode%sgn(body(j))))
    end do
    a_i = load / mass
  end function group_acceleration

  !> The cluster of body i (cluster_acceleration): its bodies and its candidate rows, each in
  !> increasing order (fits: no more than max_scope, max_scope_rows of them).
  subroutine cluster_of(scene, set, k, i, closed, t, v, acc, entry_scale, body, nb, rows, nr, fits)
    type(scene_type), intent(in) :: scene
    type(cluster_set_type), intent(inout) :: set
    integer, intent(in) :: k, i
    logical, intent(in) :: closed(:)
    real(wp), intent(in) :: t, v(:), acc(:), entry_scale(:)
    integer, intent(out) :: body(:), nb, rows(:), nr
    logical, intent(out) :: fits
    integer :: head, b, p, j, other
    set%stamp = set%stamp + 1
    set%mark(i) = set%stamp
    body(1) = i
    nb = 1
    nr = 0
    head = 0
    fits = .true.
    do while (head < nb)
      head = head + 1
      b = body(head)
      do p = set%row_start(b), set%row_start(b + 1) - 1
        j = set%row_list(p)
        if (.not. closed(j) .or. j == k) cycle
        if (abs(row_velocity(scene, j, v, t)) > u_tolerance(scene, j, v, acc, entry_scale)) cycle
        ! (each row once: from its b end, which every row has)
        if (scene%row_body(2, j) == b) then
          fits = nr < size(rows)
          if (.not. fits) return
          nr = nr + 1
          rows(nr) = j
        end if
        other = scene%row_body(1, j) + scene%row_body(2, j) - b
        if (scene%row_body(1, j) == 0 .or. set%mark(other) == set%stamp) cycle
        fits = nb < size(body)
        if (.not. fits) return
        set%mark(other) = set%stamp
        nb = nb + 1
        body(nb) = other
      end do
    end do
    call sort_increasing(body(:nb))
    call sort_increasing(rows(:nr))
  end subroutine cluster_of

  !> The mode of a scene without friction or moving grounds as solve_body_mode solves it, at
  !> the cost of the clusters that need a solve (those of candidate rows: closed rows listed
  !> in work%closed_rows) and of the ones solved last time: every other body is alone (not
  !> stuck, no sliding direction, its own group), every other row free. Each cluster is found
  !> breadth first (cluster_of: the candidate predicate of nbody_event_point), solved by
  !> solve_cluster and grouped as set_groups groups it (cluster_groups). A cluster past
  !> max_scope bodies, or a failed solve, takes solve_body_mode over all, which sets every
  !> entry (and its status is the run's).
  subroutine scoped_mode(scene, work, closed, f, df, acc, entry_scale, t, v, candidate, mode, status)
    type(scene_type), intent(in) :: scene
    type(point_work_type), intent(inout) :: work
    logical, intent(in) :: closed(:), candidate(:)
    real(wp), intent(in) :: f(:), df(:), acc(:), entry_scale(:), t, v(:)
    type(body_mode_type), intent(inout) :: mode
    integer, intent(out) :: status
    integer :: body(max_scope), rows(max_scope_rows), nb, nr, p, i, k
    logical :: fits
    call scratch_mode(mode, work)
    if (work%mode_tracked) then
      do p = 1, work%n_mode_bodies
        call alone(work%mode_bodies(p))
      end do
      mode%active(work%mode_rows(:work%n_mode_rows)) = .false.
    else
      do i = 1, scene%n_bodies
        call alone(i)
      end do
      mode%active = .false.
    end if
    work%n_mode_bodies = 0
    work%n_mode_rows = 0
    work%mode_tracked = .true.
    mode%held = .false.
    status = mode_solved
    do p = 1, work%n_closed
      k = work%closed_rows(p)
      if (.not. candidate(k)) cycle
      ! (a cluster already solved: its bodies are listed)
      if (any(work%mode_bodies(:work%n_mode_bodies) == scene%row_body(2, k))) cycle
      call cluster_of(scene, work%incidence, 0, scene%row_body(2, k), closed, t, v, acc, entry_scale, body, nb, &
        rows, nr, fits)
      if (fits) then
        work%mode_bodies(work%n_mode_bodies + 1:work%n_mode_bodies + nb) = body(:nb)
        work%mode_rows(work%n_mode_rows + 1:work%n_mode_rows + nr) = rows(:nr)
        work%n_mode_bodies = work%n_mode_bodies + nb
        work%n_mode_rows = work%n_mode_rows + nr
        work%mode%first(1:2) = [1, nb + 1]
        work%mode%member(1:nb) = body(:nb)
        work%mode%first_row(1:2) = [1, nr + 1]
        work%mode%row(1:nr) = rows(:nr)
        call solve_cluster(scene, work%mode, 1, f, df, v, t, mode, status)
      end if
      if (.not. fits .or. status /= mode_solved) then
        call solve_body_mode(scene, work%mode, f, df, v, t, candidate, mode, status)
        work%mode_tracked = .false.
        return
      end if
      call cluster_groups(scene, mode, body(:nb), rows(:nr))
    end do

  contains

    !> Body j as solve_body_mode leaves a body in no cluster, without friction.
    subroutine alone(j)
      integer, intent(in) :: j
      mode%stuck(j) = .false.
      mode%sgn(j) = 0.0_wp
      mode%group(j) = j
      mode%group_mass(j) = 0.0_wp + scene%body_mass(j)
      mode%f_slide(j) = -scene%body_friction(j) * mode%sgn(j)
    end subroutine alone
  end subroutine scoped_mode

  !> set_groups over one solved cluster (its bodies and rows in increasing order): a group's
  !> id is its least body (0: joined to the ground or a stuck body), as set_groups' union-find
  !> leaves it; its mass summed in body order; the sliding forces; held.
  subroutine cluster_groups(scene, mode, body, rows)
    type(scene_type), intent(in) :: scene
    type(body_mode_type), intent(inout) :: mode
    integer, intent(in) :: body(:), rows(:)
    integer :: root(0:size(body)), j, p, r
    logical :: joined
    root = [(j, j = 0, size(body))]
    do j = 1, size(body)
      if (mode%stuck(body(j))) root(j) = 0
      mode%group_mass(body(j)) = 0.0_wp
    end do
    do p = 1, size(rows)
      if (mode%active(rows(p))) joined = uf_join(root, local_of(scene%row_body(1, rows(p))), &
        local_of(scene%row_body(2, rows(p))))
    end do
    do j = 1, size(body)
      r = uf_find(root, j)
      mode%group(body(j)) = 0
      if (r > 0) mode%group(body(j)) = body(r)
      if (r > 0) mode%group_mass(body(r)) = mode%group_mass(body(r)) + scene%body_mass(body(j))
      mode%f_slide(body(j)) = -scene%body_friction(body(j)) * mode%sgn(body(j))
    end do
    mode%held = mode%held .or. any(mode%active(rows)) .or. any(mode%stuck(body))

  contains

    !> Body i's number in the cluster (0: the ground).
    integer function local_of(i)
      integer, intent(in) :: i
      local_of = 0
      if (i > 0) local_of = findloc(body, i, 1)
    end function local_of
  end subroutine cluster_groups

  !> Insertion sort (a cluster's few bodies or rows).
  pure subroutine sort_increasing(list)
    integer, intent(inout) :: list(:)
    integer :: j, p, item
    do j = 2, size(list)
      item = list(j)
      p = j - 1
      do while (p >= 1)
        if (list(p) <= item) exit
        list(p + 1) = list(p)
        p = p - 1
      end do
      list(p + 1) = item
    end do
  end subroutine sort_increasing

  !> Bodies whose velocity is below the rounding of what a step changes it by, or of the
  !> velocities this event point started from, are at rest (and with friction contacts,
  !> what moved with them in the mode: carry_stopped).
  pure subroutine zero_stopped(scene, mode, s, acc, entry_scale)
    type(scene_type), intent(in) :: scene
    type(body_mode_type), intent(in) :: mode
    type(state_type), intent(inout) :: s
    real(wp), intent(in) :: acc(:), entry_scale(:)
    logical :: zeroed(scene%n_bodies)
    integer :: i
    do i = 1, scene%n_bodies
      zeroed(i) = s%v(i) /= rest_velocity(scene, i, s%t) .and. abs(s%v(i) - rest_velocity(scene, i, s%t)) <= &
        velocity_rounding * max(abs(acc(i)) * scene%dt, entry_scale(i)) .and. .not. rides_drive(scene, mode, i, s%t)
      if (zeroed(i)) call zero_velocity(scene, s, i)
    end do
    if (scene%n_frictions > 0 .and. any(zeroed)) call carry_stopped(scene, mode, zeroed, s)
  end subroutine zero_stopped

  !> Whether body i is held to a ground that accelerates at t: its velocity is w'(t), which
  !> does not stay at zero, not a stop within rounding of it (zeroed at a turn of w', it was
  !> stuck: its friction lost while it rode the ground on, not sliding back). On a ground at
  !> constant speed (w'' = 0) a held body is zeroed as on the still ground.
  pure logical function rides_drive(scene, mode, i, t)
    type(scene_type), intent(in) :: scene
    type(body_mode_type), intent(in) :: mode
    integer, intent(in) :: i
    real(wp), intent(in) :: t
    rides_drive = .false.
    if (scene%drives%n == 0) return
    if (mode%drive(i) > 0) rides_drive = scene%drives%acceleration(mode%drive(i), t) /= 0.0_wp
  end function rides_drive

  !> The velocity at which body i rests at time t: its belt's when it has one and friction
  !> to hold it there (impact1d_friction_laws), else 0.
  pure real(wp) function rest_velocity(scene, i, t)
    type(scene_type), intent(in) :: scene
    integer, intent(in) :: i
    real(wp), intent(in) :: t
    rest_velocity = 0.0_wp
    if (scene%belts .and. scene%body_static(i) > 0.0_wp) rest_velocity = belt_speed(scene, i, t)
  end function rest_velocity

  !> Body i is at rest (rest_velocity); the rounding-level energy it had beyond that goes to
  !> friction where friction stopped it, else to impacts.
  pure subroutine zero_velocity(scene, s, i)
    type(scene_type), intent(in) :: scene
    type(state_type), intent(inout) :: s
    integer, intent(in) :: i
    if (scene%body_static(i) > 0.0_wp .and. scene%belts) then
      call add_compensated(s%friction_loss, s%friction_lo, 0.5_wp * scene%body_mass(i) * &
        (s%v(i)**2 - rest_velocity(scene, i, s%t)**2))
    else if (scene%body_static(i) > 0.0_wp) then
      call add_compensated(s%friction_loss, s%friction_lo, 0.5_wp * scene%body_mass(i) * s%v(i)**2)
    else
      s%impact_loss = s%impact_loss + 0.5_wp * scene%body_mass(i) * s%v(i)**2
    end if
    s%v(i) = rest_velocity(scene, i, s%t)
    s%v_lo(i) = 0.0_wp
  end subroutine zero_velocity

  !> The friction contacts between bodies that stick ('stick_<name>': stuck in the new mode,
  !> not in the old) or slip ('slip_<name>': stuck in the old, not in the new).
  subroutine log_pairs(scene, was_stuck, new, s, sink, stats)
    type(scene_type), intent(in) :: scene
    logical, intent(in) :: was_stuck(:)
    type(body_mode_type), intent(in) :: new
    type(state_type), intent(in) :: s
    class(sink_type), intent(inout) :: sink
    type(run_stats), intent(inout) :: stats
    integer :: j
    do j = 1, scene%n_frictions
      if (new%friction_stuck(j) .eqv. was_stuck(j)) cycle
      call log_event(scene, sink, stats, s%t, merge(class_pair_stick, class_pair_slip, new%friction_stuck(j)), &
        size(scene%row_name) + j, s%v, s%v)
    end do
  end subroutine log_pairs

  !> Friction contact j's ends, with the bodies the mode moves with each (their groups),
  !> given one velocity at its located relative stop: their common one (momentum kept), or
  !> that of an end held still; the kinetic energy of the rounding left is friction's.
  pure subroutine relative_rest(scene, mode, j, s)
    type(scene_type), intent(in) :: scene
    type(body_mode_type), intent(in) :: mode
    integer, intent(in) :: j
    type(state_type), intent(inout) :: s
    real(wp) :: v, momentum, mass, before
    integer :: i, ga, gb
    ga = mode%group(scene%friction_body(1, j))
    gb = mode%group(scene%friction_body(2, j))
    momentum = 0.0_wp
    mass = 0.0_wp
    before = 0.0_wp
    do i = 1, scene%n_bodies
      if (.not. moved(i)) cycle
      momentum = momentum + scene%body_mass(i) * s%v(i)
      mass = mass + scene%body_mass(i)
      before = before + 0.5_wp * scene%body_mass(i) * s%v(i)**2
    end do
    v = 0.0_wp
    if (mass > 0.0_wp) v = momentum / mass
    if (ga == 0) v = s%v(scene%friction_body(1, j))
    if (gb == 0) v = s%v(scene%friction_body(2, j))
    call add_compensated(s%friction_loss, s%friction_lo, before - 0.5_wp * mass * v**2)
    do i = 1, scene%n_bodies
      if (.not. moved(i)) cycle
      s%v(i) = v
      s%v_lo(i) = 0.0_wp
    end do

  contains

    !> Whether body i moves with an end of the contact (not held still).
    pure logical function moved(i)
      integer, intent(in) :: i
      moved = mode%group(i) /= 0 .and. (mode%group(i) == ga .or. mode%group(i) == gb)
    end function moved
  end subroutine relative_rest

  !> The bodies that moved in one group with a body friction has just stopped (joined by
  !> friction contacts stuck in the old mode: their velocities were equal) take its velocity,
  !> the rounding-level energy booked to friction. On a belt the stopped body is put at the
  !> belt's speed, which its partners (not at rest on their own) would otherwise miss by
  !> the rounding: the contact would then seem to slide, and slip and stick at once.
  pure subroutine carry_stopped(scene, mode, stopped, s)
    type(scene_type), intent(in) :: scene
    type(body_mode_type), intent(in) :: mode
    logical, intent(in) :: stopped(:)
    type(state_type), intent(inout) :: s
    real(wp) :: carried(0:scene%n_bodies)
    logical :: halted(0:scene%n_bodies)
    integer :: i
    halted = .false.
    do i = 1, scene%n_bodies
      if (.not. stopped(i) .or. mode%group(i) == 0) cycle
      halted(mode%group(i)) = .true.
      carried(mode%group(i)) = s%v(i)
    end do
    do i = 1, scene%n_bodies
      if (stopped(i) .or. .not. halted(mode%group(i))) cycle
      call add_compensated(s%friction_loss, s%friction_lo, 0.5_wp * scene%body_mass(i) * &
        (s%v(i)**2 - carried(mode%group(i))**2))
      s%v(i) = carried(mode%group(i))
      s%v_lo(i) = 0.0_wp
    end do
  end subroutine carry_stopped

  !> Kinetic energy of the bodies at velocities v.
  pure real(wp) function kinetic(scene, v)
    type(scene_type), intent(in) :: scene
    real(wp), intent(in) :: v(:)
    kinetic = 0.5_wp * dot_product(scene%body_mass, v**2)
  end function kinetic

  !> An impact cannot raise the kinetic energy beyond its rounding: if one does, the engine
  !> is wrong, and the run says so.
  !> (drive: the work moving grounds did in it, which may raise the kinetic energy.)
  subroutine check_dissipative(scene, t, v_before, v_after, drive, error)
    type(scene_type), intent(in) :: scene
    real(wp), intent(in) :: t, v_before(:), v_after(:), drive
    type(error_type), allocatable, intent(inout) :: error
    real(wp) :: ke_before, ke_after
    ke_before = kinetic(scene, v_before)
    ke_after = kinetic(scene, v_after)
    if (drive /= 0.0_wp) then
      if (ke_after - drive <= ke_before + energy_rounding * max(ke_before, ke_after, abs(drive))) return
    else if (ke_after <= ke_before * (1.0_wp + energy_rounding)) then
      return
    end if
    call raise(error, status_simulation, 'at t = ' // trim(fmt(t)) // ': internal error: an impact ' // &
      'raised the kinetic energy from ' // trim(fmt(ke_before)) // ' to ' // trim(fmt(ke_after)) // &
      ' J; please report the scene')
  end subroutine check_dissipative

  !> New velocities at an instant, the kinetic energy they remove booked as impact loss (and
  !> the work drive of moving grounds in it, which they did not take, as drive_work).
  pure subroutine apply(scene, s, v_new, drive)
    type(scene_type), intent(in) :: scene
    type(state_type), intent(inout) :: s
    real(wp), intent(in) :: v_new(:)
    real(wp), intent(in), optional :: drive
    s%impact_loss = s%impact_loss + kinetic(scene, s%v) - kinetic(scene, v_new)
    if (present(drive)) then
      s%impact_loss = s%impact_loss + drive
      call add_compensated(s%drive_work, s%drive_lo, drive)
    end if
    s%v = v_new
    s%v_lo = 0.0_wp
  end subroutine apply

  !> Log what a user can see change between the old mode and new: rows that start or stop
  !> holding, bodies that come to rest or break away (the rules of docs/method.md section 5).
  subroutine log_mode_change(scene, initial, f, df, candidate, new, s, event_log, sink, stats)
    type(scene_type), intent(in) :: scene
    logical, intent(in) :: initial, candidate(:)
    real(wp), intent(in) :: f(:), df(:)
    type(body_mode_type), intent(in) :: new
    type(state_type), intent(in) :: s
    type(event_log_type), intent(inout) :: event_log
    class(sink_type), intent(inout) :: sink
    type(run_stats), intent(inout) :: stats
    real(wp), dimension(scene%n_bodies) :: acc, tol_a, acc_rate
    real(wp) :: rate_tol, direction
    logical :: leaving, resting_now, ready
    integer :: k, i

    ! (the accelerations, their rates and tolerances only where a row leaves contact or a
    ! body has static friction: an event of frictionless bodies that no contact held needs
    ! none of these O(N) sums)
    ready = .false.
    do k = 1, scene%n_rows
      if (new%active(k) .and. .not. event_log%in_contact(k)) then
        call event_log%begin_rest(scene, k, s%t, s%t, s%v, sink, stats)
      else if (event_log%in_contact(k) .and. .not. new%active(k)) then
        call prepare()
        if (.not. candidate(k) .or. row_acceleration(k, acc, 2) > row_abs_tol(k, tol_a) .or. &
            (row_acceleration(k, acc, 2) >= -row_abs_tol(k, tol_a) .and. &
            row_acceleration(k, acc_rate, 3) > rate_tol / minval(scene%body_mass))) then
          if (event_log%pending_rest(k) < huge(1.0_wp)) then
            call log_event(scene, sink, stats, s%t, class_rest, k, s%v, s%v)
            event_log%pending_rest(k) = huge(1.0_wp)
          end if
          event_log%in_contact(k) = .false.
          event_log%release_time(k) = s%t
          event_log%release_v(:, k) = pair_of(k, s%v)
        end if
      end if
    end do
    do i = 1, scene%n_bodies
      if (scene%body_static(i) == 0.0_wp) cycle
      call prepare()
      ! Its sliding direction; a body that breaks away with no sliding friction has none
      ! (sgn 0): the way it accelerates.
      direction = new%sgn(i)
      if (direction == 0.0_wp) direction = sign(1.0_wp, merge(acc(i), acc_rate(i), acc(i) /= 0.0_wp))
      leaving = direction * acc(i) > tol_a(i) .or. (direction * acc(i) >= -tol_a(i) .and. &
        direction * acc_rate(i) > rate_tol / scene%body_mass(i))
      resting_now = slip(scene, i, s%v(i), s%t) == 0.0_wp .and. .not. leaving
      if (resting_now .and. .not. event_log%at_rest(i) .and. .not. initial .and. &
          .not. same_instant(scene, s%t, event_log%rest_lost_time(i))) &
        call log_event(scene, sink, stats, s%t, class_stick, i, s%v, s%v)
      if (.not. resting_now .and. event_log%at_rest(i)) then
        if (slip(scene, i, s%v(i), s%t) == 0.0_wp) then
          call log_event(scene, sink, stats, s%t, class_slip, i, s%v, s%v)
        else
          event_log%rest_lost_time(i) = s%t
        end if
      end if
      event_log%at_rest(i) = resting_now
    end do

  contains

    !> acc, acc_rate, tol_a and rate_tol, once.
    subroutine prepare()
      if (ready) return
      ready = .true.
      call mode_acceleration(scene, new, s%t, f, acc)
      if (scene%geared) then
        call new%geared_response(df, acc_rate)
      else
        call new%rate_response(df, acc_rate)
      end if
      if (scene%drives%n > 0) call drive_accelerations(scene, new, s%t, 3, acc_rate)
      ! (on an accelerating belt a body leaves or rests by its acceleration relative to it)
      if (scene%belt_moves) call relative_to_belts()
      tol_a = 1.0e3_wp * eps_wp * force_scale(scene, f, df) / scene%body_mass
      rate_tol = 1.0e3_wp * eps_wp * sum(abs(df))
    end subroutine prepare

    !> acc and acc_rate relative to the accelerating belts (a stuck body's: 0).
    subroutine relative_to_belts()
      integer :: j
      call belt_accelerations(scene, new%stuck, s%t, 3, acc_rate)
      do j = 1, scene%n_bodies
        if (.not. belt_moving(scene, j)) cycle
        acc(j) = acc(j) - belt_rate(scene, j, s%t, 2)
        acc_rate(j) = acc_rate(j) - belt_rate(scene, j, s%t, 3)
      end do
    end subroutine relative_to_belts

    !> Row j's gap acceleration (order 2) or its rate (3) at the bodies' a (with its moving
    !> ground end's; the accelerating belts' taken back: a is relative to them).
    real(wp) function row_acceleration(j, a, order)
      integer, intent(in) :: j, order
      real(wp), intent(in) :: a(:)
      integer :: e
      row_acceleration = row_velocity(scene, j, a)
      if (scene%drives%n > 0) row_acceleration = row_acceleration + ground_motion(scene, j, s%t, order)
      if (.not. scene%belt_moves) return
      do e = 1, 2
        if (scene%row_body(e, j) > 0) row_acceleration = row_acceleration + scene%row_normal(e, j) * &
          belt_rate(scene, scene%row_body(e, j), s%t, order)
      end do
    end function row_acceleration

    !> Row j's |n| . tol (its ends' tolerances).
    pure real(wp) function row_abs_tol(j, tol)
      integer, intent(in) :: j
      real(wp), intent(in) :: tol(:)
      row_abs_tol = tol(scene%row_body(2, j))
      if (scene%row_body(1, j) > 0) row_abs_tol = row_abs_tol + tol(scene%row_body(1, j))
    end function row_abs_tol

    !> The velocities of row j's ends (0 for the ground), as a release logs them; with one
    !> or two bodies the bodies' own, (v1, v2) or (v1, 0), which log_event reports for any
    !> row (a ground row's pair (0, v_b) was logged as v1 = 0, v2 = v_b).
    pure function pair_of(j, v) result(pair)
      integer, intent(in) :: j
      real(wp), intent(in) :: v(:)
      real(wp) :: pair(2)
      pair = 0.0_wp
      if (scene%n_bodies <= tutorial_bodies) then
        pair(:scene%n_bodies) = v
        return
      end if
      if (scene%row_body(1, j) > 0) pair(1) = v(scene%row_body(1, j))
      pair(2) = v(scene%row_body(2, j))
    end function pair_of
  end subroutine log_mode_change
end module impact1d_nbody_event

!> Scenes of any number of bodies, as written (impact1d_fields): settled after reading (a
!> chain of one or two bodies folds into the tutorial's scalars, so it means what they
!> mean), checked where no engine is needed, and carried to the model as contact and
!> element records (input_records: the layout of scene_type's records, issue 19 stage 2).
module impact1d_chain
  use, intrinsic :: ieee_arithmetic, only: ieee_is_finite, ieee_value, ieee_quiet_nan
  use impact1d_kinds, only: wp, eps_wp
  use impact1d_error, only: error_type, raise, status_input, fmt, fmt_width
  use impact1d_scene, only: tutorial_bodies
  use impact1d_scene, only: scene_input, real_names, text_names, n_real, n_text, set_text, name_of, value_or, &
    positive_value, nonnegative_value, unit_interval, resolvable, unresolved, i_m1, i_m2, i_x_left, i_r_left, i_x_right, &
    i_r_right, i_r_min, i_d_min, i_g, default_gravity, i_mu1, i_mu2, i_mus1, i_mus2, i_x1, i_x2, i_v1, i_v2, i_f1, i_f2, &
    i_f1_amp, i_f2_amp, i_f1_period, i_f2_period, i_f1_phase, i_f2_phase, i_k1, i_k2, i_x1_rest, i_x2_rest, &
    i_c1, i_c2, i_d_max, i_r_max, i_k12, i_d_rest, i_c12, i_f1_table, i_f2_table, i_x_left_v, i_x_right_v, &
    i_x_left_table, i_x_right_table
  use impact1d_forcing, only: table_value
  use impact1d_fields, only: array_value, n_arrays, array_names, array_is_link, array_is_text, alias_name, name_len, &
    record_input, a_m, a_mu, a_mus, a_x, a_f_amp, a_f_period, a_f_phase, a_k, a_x_rest, a_c, a_d_min, a_r_min, &
    a_d_max, a_r_max, a_k_link, a_d_rest, a_c_link, r_a, r_b, r_d_min, r_r_min, r_d_max, r_r_max, r_k, r_d_rest, &
    r_c, contact_fields, spring_fields, r_name, n_contact_fields, n_spring_fields, written_array, text_item, &
    a_f_table, mechanism_records, n_sine_fields, sine_fields, r_body, r_amp, r_period, r_phase, r_stop_k, r_stop_c, &
    r_ground_v, r_spring_ground_v, n_ground_fields, a_belt_v, a_v_s, a_c_v, a_belt_amp, a_belt_period, a_belt_phase, &
    n_friction_fields, friction_fields, &
    r_mu, r_mus, r_normal, r_friction_name, r_ratio, r_spring_ratio, r_ground_table, r_spring_ground_table
  implicit none
  private
  public :: settle_chain, validate_chain, input_records, mechanism_records, n_bodies_of, slot_of, alias_slot, check_start
  public :: id_arrays, id_r_meet, id_contact, id_spring, id_sine, id_friction, id_bodies_out, n_ids, field_name, &
    field_is_text, assign_number, &
    assign_text, scene_assignments

  !> The input fields' numbering (the namelist reader's and the flat API's): 1..n_real the
  !> tutorial's scalars, then its texts, the arrays (impact1d_fields' order), r_meet, the
  !> &contact record fields, the &spring record fields, the &sine record fields, the
  !> &friction record fields, &run bodies_out (element i: the i-th body written).
  integer, parameter :: id_arrays = n_real + n_text, id_r_meet = id_arrays + n_arrays + 1, &
    id_contact = id_r_meet, id_spring = id_contact + n_contact_fields, id_sine = id_spring + n_spring_fields, &
    id_friction = id_sine + n_sine_fields, id_bodies_out = id_friction + n_friction_fields + 1, n_ids = id_bodies_out


  !> alias_slot(j, i) for i = 1, 2 (0: no such name), impact1d_fields' array order:
  !> element reads a two-body scene's arrays through it, and a search of the names by string
  !> cost 2 x 10^5 instructions per prepare_scene (3/4 of a short run's set-up).
  !> test_chain checks it against the search.
  integer, parameter :: alias_slots(2, n_arrays) = reshape([i_m1, i_m2, i_mu1, i_mu2, i_mus1, i_mus2, &
    i_x1, i_x2, i_v1, i_v2, i_f1, i_f2, i_f1_amp, i_f2_amp, i_f1_period, i_f2_period, i_f1_phase, i_f2_phase, &
    i_k1, i_k2, i_x1_rest, i_x2_rest, i_c1, i_c2, i_d_min, 0, i_r_min, 0, i_d_max, 0, i_r_max, 0, i_k12, 0, &
    i_d_rest, 0, i_c12, 0, n_real + i_f1_table, n_real + i_f2_table, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0], [2, n_arrays])

  !> Arrays whose elements must not be negative.
  integer, parameter :: nonnegative_arrays(6) = [a_mu, a_mus, a_k, a_c, a_k_link, a_c_link]

contains

  !> After reading: N (the length of m, else the tutorial's m1/m2), every array of the right
  !> length, no element given twice (as m1 and in m), and a chain of one or two bodies
  !> folded into the tutorial's scalars (its elements spelled 'm(2)' in messages).
  subroutine settle_chain(input, error)
    type(scene_input), intent(inout) :: input
    type(error_type), allocatable, intent(out) :: error
    integer :: n, j
    n = merge(2, 1, input%given(i_m2))
    if (input%chain%array(a_m)%n > 0) n = input%chain%array(a_m)%n
    do j = 1, n_arrays
      call check_length(input, j, n, error)
      if (allocated(error)) return
    end do
    if (n > tutorial_bodies) then
      call refuse_two_body_names(input, n, error)
      input%chain%n_bodies = n
      return
    end if
    do j = 1, n_arrays
      call fold(input, j, error)
      if (allocated(error)) return
    end do
    if (input%chain%has_r_meet) call fold_meeting(input, n, error)
  end subroutine settle_chain

  !> Array j holds N values (a body array) or N - 1 (a link array) when written.
  subroutine check_length(input, j, n, error)
    type(scene_input), intent(in) :: input
    integer, intent(in) :: j, n
    type(error_type), allocatable, intent(inout) :: error
    integer :: wanted
    associate (written => input%chain%array(j)%n)
      wanted = merge(n - 1, n, array_is_link(j))
      if (written == 0 .or. written == wanted) return
      if (array_is_link(j)) then
        call raise(error, status_input, trim(array_names(j)) // ' has ' // trim(fmt(written)) // &
          ' values, but &link arrays hold one per link, N - 1 = ' // trim(fmt(wanted)) // ' (' // &
          trim(bodies_text(input, n)) // ')')
      else
        call raise(error, status_input, trim(array_names(j)) // ' has ' // trim(fmt(written)) // &
          ' values, but body arrays hold one per body, N = ' // trim(fmt(n)) // ' (' // &
          trim(bodies_text(input, n)) // ')')
      end if
    end associate
  end subroutine check_length

  !> How the scene's N came about, for messages.
  pure function bodies_text(input, n) result(text)
    type(scene_input), intent(in) :: input
    integer, intent(in) :: n
    character(len=48) :: text     ! blank padded: callers trim
    if (input%chain%array(a_m)%n > 0) then
      text = 'm has ' // trim(fmt(n)) // ' values'
    else
      text = trim(merge('m1 and m2 given', 'm1 alone       ', n == 2))
    end if
  end function bodies_text

  !> In a scene of N > 2 bodies the tutorial's numbered names (x1, k12, d_min alone) have no
  !> meaning: each array is written whole.
  subroutine refuse_two_body_names(input, n, error)
    type(scene_input), intent(in) :: input
    integer, intent(in) :: n
    type(error_type), allocatable, intent(inout) :: error
    integer :: j, i, slot
    do j = 1, n_arrays
      do i = 1, 2
        slot = alias_slot(j, i)
        if (slot == 0) cycle
        if (.not. given_slot(input, slot)) cycle
        call raise(error, status_input, trim(alias_name(j, i)) // ' is a name of a one- or two-body scene, ' // &
          'but this one has N = ' // trim(fmt(n)) // ' bodies (m has ' // trim(fmt(n)) // ' values): write ' // &
          trim(array_names(j)) // ' as an array of ' // trim(fmt(merge(n - 1, n, array_is_link(j)))) // ' values')
        return
      end do
    end do
  end subroutine refuse_two_body_names

  !> Array j of a one- or two-body chain into the tutorial's scalars, element i spelled
  !> '<name>(i)'; refused when the scalar is given too. An array without a tutorial name
  !> (the friction laws': belt_v, v_s, c_v) stays an array.
  subroutine fold(input, j, error)
    type(scene_input), intent(inout) :: input
    integer, intent(in) :: j
    type(error_type), allocatable, intent(inout) :: error
    integer :: i, slot
    character(len=16) :: spelled
    if (alias_slot(j, 1) == 0) return
    do i = 1, input%chain%array(j)%n
      slot = alias_slot(j, i)
      write(spelled, '(a, "(", i0, ")")') trim(array_names(j)), i
      if (given_slot(input, slot)) then
        call raise(error, status_input, trim(alias_name(j, i)) // ' is given and so is ' // trim(array_names(j)) // &
          ' (' // trim(alias_name(j, i)) // ' is ' // trim(spelled) // '): give one of them')
        return
      end if
      if (array_is_text(j)) then
        call set_text(input, slot - n_real, input%chain%array(j)%t(i)%s)
      else
        input%value(slot) = input%chain%array(j)%v(i)
        input%given(slot) = .true.
        input%spelled(slot) = spelled
      end if
    end do
    input%chain%array(j)%n = 0
  end subroutine fold

  !> r_meet of a two-body scene is r_min without d_min, the restitution of the bodies' meeting.
  subroutine fold_meeting(input, n, error)
    type(scene_input), intent(inout) :: input
    integer, intent(in) :: n
    type(error_type), allocatable, intent(inout) :: error
    if (n == 1) then
      call raise(error, status_input, 'r_meet is given but m2 is not: a scene without m2 has one body ' // &
        '(give m2 for a second one)')
    else if (input%given(i_r_min) .and. .not. input%given(i_d_min)) then
      call raise(error, status_input, 'r_meet and ' // trim(name_of(input, i_r_min)) // ' both give the ' // &
        'restitution of the bodies'' meeting: give one of them')
    else if (.not. input%given(i_d_min)) then
      input%value(i_r_min) = input%chain%r_meet
      input%given(i_r_min) = .true.
      input%spelled(i_r_min) = 'r_meet'
    end if
    input%chain%has_r_meet = .false.
  end subroutine fold_meeting

  !> Scalar slot (1..n_real) or text slot (n_real + 1..) of a tutorial name; 0 if none.
  pure integer function slot_of(name)
    character(len=*), intent(in) :: name
    integer :: k
    slot_of = 0
    if (len_trim(name) == 0) return
    do k = 1, n_real
      if (real_names(k) == name) slot_of = k
    end do
    do k = 1, n_text
      if (text_names(k) == name) slot_of = n_real + k
    end do
  end function slot_of

  !> The slot of the tutorial's name of element i of array j ('m2', 'k12'), 0 when it has none.
  pure integer function alias_slot(j, i)
    integer, intent(in) :: j, i
    alias_slot = 0
    if (i == 1 .or. i == 2) alias_slot = alias_slots(i, j)
  end function alias_slot

  !> Whether slot k (a scalar, or n_real + a text) is given.
  pure logical function given_slot(input, k)
    type(scene_input), intent(in) :: input
    integer, intent(in) :: k
    given_slot = .false.
    if (k >= 1 .and. k <= n_real) given_slot = input%given(k)
    if (k > n_real) given_slot = len_trim(input%text(k - n_real)%s) > 0
  end function given_slot

  !> N: the length of m in an N-body scene, else 2 with m2, 1 without.
  pure integer function n_bodies_of(input)
    type(scene_input), intent(in) :: input
    n_bodies_of = merge(2, 1, input%given(i_m2))
    if (input%chain%n_bodies > tutorial_bodies) n_bodies_of = input%chain%n_bodies
  end function n_bodies_of

  !> Element i of array j as the scene gives it (given false: absent, value 0).
  pure subroutine element(input, j, i, value, given)
    type(scene_input), intent(in) :: input
    integer, intent(in) :: j, i
    real(wp), intent(out) :: value
    logical, intent(out) :: given
    integer :: slot
    value = 0.0_wp
    given = .false.
    if (input%chain%n_bodies > tutorial_bodies) then
      given = input%chain%array(j)%n >= i
      value = array_value(input%chain, j, i, 0.0_wp)
    else
      slot = alias_slot(j, i)
      if (slot < 1 .or. slot > n_real) return
      given = input%given(slot)
      value = input%value(slot)
    end if
  end subroutine element

  !> Element i of array j, or default when absent.
  pure real(wp) function element_or(input, j, i, default)
    type(scene_input), intent(in) :: input
    integer, intent(in) :: j, i
    real(wp), intent(in) :: default
    logical :: given
    call element(input, j, i, element_or, given)
    if (.not. given) element_or = default
  end function element_or

  !> Whether element i of array j is given.
  pure logical function has_element(input, j, i)
    type(scene_input), intent(in) :: input
    integer, intent(in) :: j, i
    real(wp) :: value
    call element(input, j, i, value, has_element)
  end function has_element

  !> 'm(3)' (N > 2) or the tutorial's spelling, for messages.
  pure function element_name(input, j, i) result(name)
    type(scene_input), intent(in) :: input
    integer, intent(in) :: j, i
    character(len=24) :: name     ! blank padded: callers trim
    if (input%chain%n_bodies > tutorial_bodies) then
      write(name, '(a, "(", i0, ")")') trim(array_names(j)), i
    else
      name = name_of(input, alias_slot(j, i))
    end if
  end function element_name

  !> What needs no engine, after validate: an N-body scene's arrays element by element, the
  !> records (ends, limits, names) and the initial state inside every contact.
  !> checked_records, when present, takes the records it checked (input_records'): the caller
  !> that builds the scene from them need not make them again (18 allocations).
  subroutine validate_chain(input, error, checked_records)
    type(scene_input), intent(in) :: input
    type(error_type), allocatable, intent(out) :: error
    type(mechanism_records), intent(out), optional :: checked_records
    type(mechanism_records) :: records
    if (present(checked_records)) then
      call check_chain(input, checked_records, error)
    else
      call check_chain(input, records, error)
    end if
  end subroutine validate_chain

  !> validate_chain's checks, the records made on the way (not made after an error in the
  !> arrays or the records' fields).
  subroutine check_chain(input, records, error)
    type(scene_input), intent(in) :: input
    type(mechanism_records), intent(out) :: records
    type(error_type), allocatable, intent(out) :: error
    if (input%chain%n_bodies > tutorial_bodies) call check_arrays(input, error)
    if (allocated(error)) return
    call check_laws(input, error)
    if (allocated(error)) return
    if (allocated(input%chain%contacts)) call check_records(input, input%chain%contacts, .true., error)
    if (allocated(error)) return
    if (allocated(input%chain%springs)) call check_records(input, input%chain%springs, .false., error)
    if (allocated(error)) return
    if (allocated(input%chain%sines)) call check_sines(input, error)
    if (allocated(error)) return
    if (allocated(input%chain%frictions)) call check_frictions(input, error)
    if (allocated(error)) return
    call wall_motion_terms(input, error)
    if (allocated(error)) return
    call input_records(input, records)
    call check_names(records, error)
    if (allocated(error)) return
    call check_start(input, records, error)
  end subroutine check_chain

  !> An N-body scene's arrays: finite, x given, masses positive, coefficients not negative,
  !> static friction at least sliding, pairs that go together, slot limits in order.
  subroutine check_arrays(input, error)
    type(scene_input), intent(in) :: input
    type(error_type), allocatable, intent(inout) :: error
    integer :: j, i, n
    n = input%chain%n_bodies
    do j = 1, n_arrays
      if (array_is_text(j) .or. input%chain%array(j)%n == 0) cycle
      do i = 1, input%chain%array(j)%n
        if (.not. ieee_is_finite(input%chain%array(j)%v(i))) then
          call raise(error, status_input, trim(element_name(input, j, i)) // ' = ' // &
            trim(fmt(input%chain%array(j)%v(i))) // ' is not a finite number')
          return
        end if
      end do
    end do
    if (input%chain%array(a_x)%n == 0) then
      call raise(error, status_input, 'x is required but not given (one initial position per body)')
      return
    end if
    do i = 1, n
      call positive_value(trim(element_name(input, a_m, i)), element_or(input, a_m, i, 1.0_wp), error)
      do j = 1, size(nonnegative_arrays)
        if (has_element(input, nonnegative_arrays(j), i)) call nonnegative_value( &
          trim(element_name(input, nonnegative_arrays(j), i)), element_or(input, nonnegative_arrays(j), i, 0.0_wp), error)
      end do
      if (element_or(input, a_mus, i, huge(1.0_wp)) < element_or(input, a_mu, i, 0.0_wp)) call raise(error, &
        status_input, trim(element_name(input, a_mus, i)) // ' = ' // trim(fmt(element_or(input, a_mus, i, 0.0_wp))) // &
        ' is below ' // trim(element_name(input, a_mu, i)) // ' = ' // trim(fmt(element_or(input, a_mu, i, 0.0_wp))) // &
        ': static friction is at least the sliding friction')
      if (allocated(error)) return
    end do
    call together(input, a_k, a_x_rest, .true., 'a spring needs its rest position', error)
    call together(input, a_k_link, a_d_rest, .true., 'a spring needs its rest length', error)
    call together(input, a_f_amp, a_f_period, .true., 'a sine force needs both', error)
    call together(input, a_f_phase, a_f_amp, .false., 'a phase needs its sine', error)
    call together(input, a_r_max, a_d_max, .false., 'a restitution needs its limit', error)
    if (allocated(error)) return
    call check_link_arrays(input, n, error)
  end subroutine check_arrays

  !> The friction laws' arrays (kept as arrays for any N: fold): belt_v, belt_amp,
  !> belt_phase finite, v_s and belt_period positive, c_v not negative, a belt's sine whole
  !> (docs/formats.md, "Friction laws").
  subroutine check_laws(input, error)
    type(scene_input), intent(in) :: input
    type(error_type), allocatable, intent(inout) :: error
    integer :: j, i
    character(len=24) :: name
    do j = a_belt_v, a_belt_phase
      do i = 1, input%chain%array(j)%n
        write(name, '(a, "(", i0, ")")') trim(array_names(j)), i
        associate (value => input%chain%array(j)%v(i))
          if (.not. ieee_is_finite(value)) then
            call raise(error, status_input, trim(name) // ' = ' // trim(fmt(value)) // ' is not a finite number')
          else if (j == a_v_s .or. j == a_belt_period) then
            call positive_value(trim(name), value, error)
          else if (j == a_c_v) then
            call nonnegative_value(trim(name), value, error)
          end if
        end associate
        if (allocated(error)) return
      end do
    end do
    call together(input, a_belt_amp, a_belt_period, .true., 'a belt''s sine speed needs both', error)
    call together(input, a_belt_phase, a_belt_amp, .false., 'a phase needs its sine', error)
  end subroutine check_laws

  !> Array j1 (say k) needs j2 (x_rest); and j2 needs j1 when both_ways.
  subroutine together(input, j1, j2, both_ways, why, error)
    type(scene_input), intent(in) :: input
    integer, intent(in) :: j1, j2
    logical, intent(in) :: both_ways
    character(len=*), intent(in) :: why
    type(error_type), allocatable, intent(inout) :: error
    if (allocated(error)) return
    if ((input%chain%array(j1)%n > 0) .eqv. (input%chain%array(j2)%n > 0)) return
    if (input%chain%array(j1)%n > 0) then
      call raise(error, status_input, trim(array_names(j1)) // ' is given but ' // trim(array_names(j2)) // &
        ' is not: ' // why)
    else if (both_ways) then
      call raise(error, status_input, trim(array_names(j2)) // ' is given but ' // trim(array_names(j1)) // &
        ' is not: ' // why)
    end if
  end subroutine together

  !> Periods positive, restitutions in [0, 1], each link's limits in order, g not pulling
  !> bodies with friction off the surface.
  subroutine check_link_arrays(input, n, error)
    type(scene_input), intent(in) :: input
    integer, intent(in) :: n
    type(error_type), allocatable, intent(inout) :: error
    integer :: i
    do i = 1, n
      if (has_element(input, a_f_period, i)) call positive_value(trim(element_name(input, a_f_period, i)), &
        element_or(input, a_f_period, i, 0.0_wp), error)
      if (element_or(input, a_mu, i, 0.0_wp) > 0.0_wp .or. element_or(input, a_mus, i, 0.0_wp) > 0.0_wp) then
        if (value_or(input, i_g, default_gravity) < 0.0_wp) call raise(error, status_input, 'g = ' // &
          trim(fmt(input%value(i_g))) // ' is negative with friction: the normal force m g must not pull ' // &
          'the bodies off the surface')
      end if
      if (allocated(error)) return
    end do
    if (input%chain%has_r_meet) call unit_interval('r_meet', input%chain%r_meet, error)
    do i = 1, n - 1
      if (has_element(input, a_r_min, i)) call unit_interval(trim(element_name(input, a_r_min, i)), &
        element_or(input, a_r_min, i, 0.0_wp), error)
      if (has_element(input, a_r_max, i)) call unit_interval(trim(element_name(input, a_r_max, i)), &
        element_or(input, a_r_max, i, 0.0_wp), error)
      if (allocated(error)) return
      call limits_in_order(trim(element_name(input, a_d_min, i)), trim(element_name(input, a_d_max, i)), &
        has_element(input, a_d_min, i), element_or(input, a_d_min, i, 0.0_wp), &
        has_element(input, a_d_max, i), element_or(input, a_d_max, i, 0.0_wp), .true., error)
      if (allocated(error)) return
    end do
  end subroutine check_link_arrays

  !> d_min <= d_max; a negative d_max without d_min when the bodies meet (d_min = 0).
  subroutine limits_in_order(lower_name, upper_name, has_lower, lower, has_upper, upper, meet, error)
    character(len=*), intent(in) :: lower_name, upper_name
    logical, intent(in) :: has_lower, has_upper, meet
    real(wp), intent(in) :: lower, upper
    type(error_type), allocatable, intent(inout) :: error
    if (allocated(error) .or. .not. has_upper) return
    if (has_lower .and. lower > upper) then
      call raise(error, status_input, lower_name // ' = ' // trim(fmt(lower)) // ' must not exceed ' // &
        upper_name // ' = ' // trim(fmt(upper)))
    else if (.not. has_lower .and. meet .and. upper < 0.0_wp) then
      call raise(error, status_input, upper_name // ' = ' // trim(fmt(upper)) // ' is negative, but without ' // &
        lower_name // ' the bodies meet (' // lower_name // ' = 0): give ' // lower_name // ' to let them pass')
    end if
  end subroutine limits_in_order

  !> Each record: its ends body numbers 0..N, not equal; a contact with a limit, a spring
  !> with an element; values finite, restitutions in [0, 1] beside their limits,
  !> stiffness and damping not negative, a spring with its rest length.
  subroutine check_records(input, records, contact, error)
    type(scene_input), intent(in) :: input
    type(record_input), intent(in) :: records(:)
    logical, intent(in) :: contact
    type(error_type), allocatable, intent(inout) :: error
    integer :: r, f
    character(len=:), allocatable :: where
    do r = 1, size(records)
      associate (rec => records(r))
        call record_place(trim(merge('&contact', '&spring ', contact)), rec, r, where)
        do f = 1, merge(size(contact_fields), size(spring_fields), contact)
          if (contact .and. f == r_name) cycle
          if (f == merge(r_ground_table, r_spring_ground_table, contact)) cycle
          if (rec%given(f) .and. .not. ieee_is_finite(rec%value(f))) call raise(error, status_input, where // &
            trim(field_of(contact, f)) // ' = ' // trim(fmt(rec%value(f))) // ' is not a finite number')
        end do
        if (.not. allocated(error)) call check_ends(rec, n_bodies_of(input), where, error)
        if (allocated(rec%name) .and. .not. allocated(error)) then
          if (len(rec%name) > name_len) call raise(error, status_input, where // "name = '" // rec%name // &
            "' is longer than " // trim(fmt(name_len)) // ' characters')
        end if
        if (contact .and. .not. allocated(error)) then
          call contact_limits(rec, where, error)
        else if (.not. allocated(error)) then
          call spring_values(rec, where, error)
        end if
        if (.not. allocated(error)) call ground_motion(rec, merge(r_ground_v, r_spring_ground_v, contact), &
          merge(r_ground_table, r_spring_ground_table, contact), where, error)
        if (.not. allocated(error)) call gear_ratio(rec, contact, where, error)
        if (allocated(error)) return
      end associate
    end do
  end subroutine check_records

  !> Where record r of a group is, for messages: its line, or (a record from Python has no
  !> line) its place among the records.
  pure subroutine record_place(group, rec, r, where)
    character(len=*), intent(in) :: group
    type(record_input), intent(in) :: rec
    integer, intent(in) :: r
    character(len=:), allocatable, intent(out) :: where
    if (rec%line == 0) then
      where = group // ' record ' // trim(fmt(r)) // ': '
    else
      where = group // ' (line ' // trim(fmt(rec%line)) // '): '
    end if
  end subroutine record_place

  !> Each &sine record: body, amp and period given (phase optional), each finite, body one
  !> of the bodies 1..N (a force acts on a body, not on the ground), period positive.
  subroutine check_sines(input, error)
    type(scene_input), intent(in) :: input
    type(error_type), allocatable, intent(inout) :: error
    integer :: r, f
    character(len=:), allocatable :: where
    do r = 1, size(input%chain%sines)
      associate (rec => input%chain%sines(r))
        call record_place('&sine', rec, r, where)
        do f = 1, n_sine_fields
          if (.not. rec%given(f) .and. f /= r_phase) then
            call raise(error, status_input, where // trim(sine_fields(f)) // ' is required but not given ' // &
              '(&sine body = 1, amp = 1.0, period = 0.5, phase = 0.0 /: phase may be left out)')
          else if (rec%given(f) .and. .not. ieee_is_finite(rec%value(f))) then
            call raise(error, status_input, where // trim(sine_fields(f)) // ' = ' // trim(fmt(rec%value(f))) // &
              ' is not a finite number')
          end if
          if (allocated(error)) return
        end do
        associate (body => rec%value(r_body), n => n_bodies_of(input))
          if (body /= aint(body) .or. body < 1.0_wp .or. body > n) call raise(error, status_input, where // &
            'body = ' // trim(fmt(body)) // ' is not a body: the bodies are 1 to N = ' // trim(fmt(n)))
        end associate
        call positive_value(where // 'period', rec%value(r_period), error)
        if (allocated(error)) return
      end associate
    end do
  end subroutine check_sines

  !> Each &friction record: a, b, mu and normal given (mus optional: mu), each finite; a and
  !> b two different bodies (friction against the ground is the body's own mu, mus: a
  !> ground end is refused), mu and normal not negative, mus >= mu (static above sliding).
  subroutine check_frictions(input, error)
    type(scene_input), intent(in) :: input
    type(error_type), allocatable, intent(inout) :: error
    integer :: r, f
    character(len=:), allocatable :: where
    do r = 1, size(input%chain%frictions)
      associate (rec => input%chain%frictions(r))
        call record_place('&friction', rec, r, where)
        do f = 1, r_normal
          if (.not. rec%given(f) .and. f /= r_mus) then
            call raise(error, status_input, where // trim(friction_fields(f)) // ' is required but not given ' // &
              '(&friction a = 1, b = 2, mu = 0.3, mus = 0.4, normal = 9.81 /: mus may be left out)')
          else if (rec%given(f) .and. .not. ieee_is_finite(rec%value(f))) then
            call raise(error, status_input, where // trim(friction_fields(f)) // ' = ' // trim(fmt(rec%value(f))) // &
              ' is not a finite number')
          end if
          if (allocated(error)) return
        end do
        call friction_ends(where, rec, n_bodies_of(input), error)
        if (allocated(error)) return
        call nonnegative_value(where // 'mu', rec%value(r_mu), error)
        call nonnegative_value(where // 'normal', rec%value(r_normal), error)
        if (allocated(error)) return
        if (rec%given(r_mus) .and. rec%value(r_mus) < rec%value(r_mu)) call raise(error, status_input, where // &
          'mus = ' // trim(fmt(rec%value(r_mus))) // ' is below mu = ' // trim(fmt(rec%value(r_mu))) // &
          ': static friction is at least sliding friction')
        if (allocated(error)) return
      end associate
    end do
  end subroutine check_frictions

  !> A &friction record's ends: two different bodies 1..n (not the ground).
  subroutine friction_ends(where, rec, n, error)
    character(len=*), intent(in) :: where
    type(record_input), intent(in) :: rec
    integer, intent(in) :: n
    type(error_type), allocatable, intent(inout) :: error
    integer :: e
    do e = 1, 2
      associate (body => rec%value(e))
        if (body == 0.0_wp) then
          call raise(error, status_input, where // trim(friction_fields(e)) // ' = 0 is the ground: friction ' // &
            'against the ground is the body''s own mu and mus (&bodies)')
        else if (body /= aint(body) .or. body < 1.0_wp .or. body > n) then
          call raise(error, status_input, where // trim(friction_fields(e)) // ' = ' // trim(fmt(body)) // &
            ' is not a body: the bodies are 1 to N = ' // trim(fmt(n)))
        end if
      end associate
      if (allocated(error)) return
    end do
    if (rec%value(1) == rec%value(2)) call raise(error, status_input, where // 'a = b = ' // &
      trim(fmt(rec%value(1))) // ': a friction contact is between two different bodies')
  end subroutine friction_ends

  !> Name of field f of a &contact (contact true) or &spring record.
  pure function field_of(contact, f) result(name)
    logical, intent(in) :: contact
    integer, intent(in) :: f
    character(len=13) :: name     ! blank padded: callers trim
    if (contact) then
      name = contact_fields(f)
    else
      name = spring_fields(f)
    end if
  end function field_of

  !> a and b given, whole numbers from 0 (the ground) to N, and different.
  subroutine check_ends(rec, n, where, error)
    type(record_input), intent(in) :: rec
    integer, intent(in) :: n
    character(len=*), intent(in) :: where
    type(error_type), allocatable, intent(inout) :: error
    integer :: f
    do f = r_a, r_b
      if (.not. rec%given(f)) then
        call raise(error, status_input, where // trim(contact_fields(f)) // ' is required but not given ' // &
          '(a body number, 0 for the ground)')
      else if (rec%value(f) /= aint(rec%value(f)) .or. rec%value(f) < 0.0_wp .or. rec%value(f) > n) then
        call raise(error, status_input, where // trim(contact_fields(f)) // ' = ' // trim(fmt(rec%value(f))) // &
          ' is not a body: the ends are 1 to N = ' // trim(fmt(n)) // ', or 0 for the ground')
      end if
      if (allocated(error)) return
    end do
    if (rec%value(r_a) == rec%value(r_b)) call raise(error, status_input, where // 'a = b = ' // &
      trim(fmt(nint(rec%value(r_a)))) // ': a record joins two different ends')
  end subroutine check_ends

  !> A contact has a limit; each restitution its limit and in [0, 1]; d_min <= d_max.
  subroutine contact_limits(rec, where, error)
    type(record_input), intent(in) :: rec
    character(len=*), intent(in) :: where
    type(error_type), allocatable, intent(inout) :: error
    integer :: f
    if (.not. (rec%given(r_d_min) .or. rec%given(r_d_max))) then
      call raise(error, status_input, where // 'a contact needs d_min or d_max (or both)')
      return
    end if
    do f = r_r_min, r_r_max, r_r_max - r_r_min
      if (.not. rec%given(f)) cycle
      if (.not. rec%given(f - 1)) then
        call raise(error, status_input, where // trim(contact_fields(f)) // ' is given but ' // &
          trim(contact_fields(f - 1)) // ' is not: a restitution needs its limit')
        return
      end if
      call unit_interval(where // trim(contact_fields(f)), rec%value(f), error)
      if (allocated(error)) return
    end do
    call limits_in_order(where // 'd_min', 'd_max', rec%given(r_d_min), rec%value(r_d_min), &
      rec%given(r_d_max), rec%value(r_d_max), .false., error)
    if (allocated(error)) return
    ! A compliant stop (k, optionally c): a stiffness > 0, a damping >= 0 beside it.
    if (rec%given(r_stop_c) .and. .not. rec%given(r_stop_k)) then
      call raise(error, status_input, where // 'c is given but k is not: a compliant stop needs its ' // &
        'stiffness k (a rigid contact has neither)')
      return
    end if
    if (rec%given(r_stop_k)) call positive_value(where // 'k', rec%value(r_stop_k), error)
    if (rec%given(r_stop_c) .and. .not. allocated(error)) call nonnegative_value(where // 'c', &
      rec%value(r_stop_c), error)
  end subroutine contact_limits

  !> The prescribed motion of a record's ground end (fields first .. first + 3: ground_v,
  !> ground_amp, ground_period, ground_phase; field table: ground_table): only on a record
  !> with a ground end (a or b = 0); a sine has its amplitude and a positive period, a phase
  !> needs its sine.
  subroutine ground_motion(rec, first, table, where, error)
    type(record_input), intent(in) :: rec
    integer, intent(in) :: first, table
    character(len=*), intent(in) :: where
    type(error_type), allocatable, intent(inout) :: error
    if (.not. (any(rec%given(first:first + n_ground_fields - 1)) .or. rec%given(table))) return
    if (rec%value(r_a) /= 0.0_wp .and. rec%value(r_b) /= 0.0_wp) then
      call raise(error, status_input, where // 'ground_v, ground_amp, ground_period, ground_phase and ' // &
        'ground_table move the ground end, but this record joins two bodies (a = 0 or b = 0 is the ground)')
      return
    end if
    call motion_terms(rec%given(first:first + n_ground_fields - 1), rec%value(first:first + n_ground_fields - 1), &
      where, 'ground', error)
  end subroutine ground_motion

  !> A prescribed motion's fields (<prefix>_v, _amp, _period, _phase: given, value; where:
  !> the record, for messages): a sine has its amplitude and a positive period, a phase
  !> needs its sine.
  subroutine motion_terms(given, value, where, prefix, error)
    logical, intent(in) :: given(n_ground_fields)
    real(wp), intent(in) :: value(n_ground_fields)
    character(len=*), intent(in) :: where, prefix
    type(error_type), allocatable, intent(inout) :: error
    if (given(2) .neqv. given(3)) then
      call raise(error, status_input, where // prefix // '_amp and ' // prefix // '_period go together: the ' // &
        'sine is ' // prefix // '_amp sin(2 pi t / ' // prefix // '_period + ' // prefix // '_phase)')
    else if (given(4) .and. .not. given(2)) then
      call raise(error, status_input, where // prefix // '_phase is given but ' // prefix // '_amp is not: a ' // &
        'phase needs its sine')
    else if (given(3)) then
      call positive_value(where // prefix // '_period', value(3), error)
    end if
  end subroutine motion_terms

  !> A record's gear ratio n (it acts on x_b - n x_a; docs/method.md section 14): positive
  !> (the sign of each shaft's angle is the user's to choose), and other than 1 only where
  !> the engine has it: between two bodies (on a ground end n x_0 = 0 leaves nothing to
  !> gear, and a ground as b only rescales the body: the limits are written in its own
  !> coordinate instead), not on a compliant stop nor a rigid link (d_min = d_max).
  subroutine gear_ratio(rec, contact, where, error)
    type(record_input), intent(in) :: rec
    logical, intent(in) :: contact
    character(len=*), intent(in) :: where
    type(error_type), allocatable, intent(inout) :: error
    integer :: f
    f = merge(r_ratio, r_spring_ratio, contact)
    if (.not. rec%given(f)) return
    call positive_value(where // 'ratio', rec%value(f), error)
    if (allocated(error) .or. rec%value(f) == 1.0_wp) return
    if (rec%value(r_a) == 0.0_wp .or. rec%value(r_b) == 0.0_wp) then
      call raise(error, status_input, where // 'ratio = ' // trim(fmt(rec%value(f))) // ' on a record with a ' // &
        'ground end (a or b = 0): a ratio gears two bodies (x_b - ratio x_a); against the ground write the ' // &
        'limits in the body''s own coordinate')
    else if (.not. contact) then
      return
    else if (rec%given(r_stop_k)) then
      call raise(error, status_input, where // 'ratio = ' // trim(fmt(rec%value(f))) // ' on a compliant stop ' // &
        '(k): geared compliant stops are not built yet')
    else if (all(rec%given([r_d_min, r_d_max]))) then
      if (rec%value(r_d_min) == rec%value(r_d_max)) call raise(error, status_input, where // 'ratio = ' // &
        trim(fmt(rec%value(f))) // ' on a rigid link (d_min = d_max): geared rigid links are not built yet ' // &
        '(give the mesh some backlash)')
    end if
  end subroutine gear_ratio

  !> The walls' prescribed motion (x_left_v ..., x_left_table, x_right_v ...): each needs its wall.
  subroutine wall_motion_terms(input, error)
    type(scene_input), intent(in) :: input
    type(error_type), allocatable, intent(inout) :: error
    integer :: side, first, wall
    character(len=7) :: prefix
    do side = 1, 2
      first = merge(i_x_left_v, i_x_right_v, side == 1)
      wall = merge(i_x_left, i_x_right, side == 1)
      prefix = merge('x_left ', 'x_right', side == 1)
      if (.not. (any(input%given(first:first + n_ground_fields - 1)) .or. &
        given_slot(input, n_real + merge(i_x_left_table, i_x_right_table, side == 1)))) cycle
      if (.not. input%given(wall)) then
        call raise(error, status_input, trim(prefix) // '_v, _amp, _period, _phase, _table move the wall ' // &
          trim(prefix) // ', which is not given')
        return
      end if
      call motion_terms(input%given(first:first + n_ground_fields - 1), input%value(first:first + n_ground_fields - 1), &
        '', trim(prefix), error)
      if (allocated(error)) return
    end do
  end subroutine wall_motion_terms

  !> The prescribed motion a record gives its ground end (fields first ..): v, amp, period,
  !> phase, 0 where not given.
  pure function ground_of(rec, first) result(ground)
    type(record_input), intent(in) :: rec
    integer, intent(in) :: first
    real(wp) :: ground(n_ground_fields)
    ground = merge(rec%value(first:first + n_ground_fields - 1), 0.0_wp, rec%given(first:first + n_ground_fields - 1))
  end function ground_of

  !> A spring has k or c (not negative); k and d_rest go together.
  subroutine spring_values(rec, where, error)
    type(record_input), intent(in) :: rec
    character(len=*), intent(in) :: where
    type(error_type), allocatable, intent(inout) :: error
    if (.not. (rec%given(r_k) .or. rec%given(r_c))) then
      call raise(error, status_input, where // 'a spring needs k or c (or both)')
    else if (rec%given(r_k) .and. .not. rec%given(r_d_rest)) then
      call raise(error, status_input, where // 'k is given but d_rest is not: a spring needs its rest length')
    else if (rec%given(r_d_rest) .and. .not. rec%given(r_k)) then
      call raise(error, status_input, where // 'd_rest is given but k is not: a rest length needs its spring')
    else
      if (rec%given(r_k)) call nonnegative_value(where // 'k', rec%value(r_k), error)
      if (rec%given(r_c)) call nonnegative_value(where // 'c', rec%value(r_c), error)
    end if
  end subroutine spring_values

  !> Contact names are unique and none starts as an event kind does (rest_, release_,
  !> stick, slip): a kind is read back as an impact on the contact of its name otherwise.
  subroutine check_names(records, error)
    type(mechanism_records), intent(in) :: records
    type(error_type), allocatable, intent(inout) :: error
    character(len=*), parameter :: reserved(4) = [character(len=8) :: 'rest_', 'release_', 'stick', 'slip']
    integer :: k, j
    do k = 1, records%n_contacts
      associate (name => records%contact_name(k))
        do j = 1, size(reserved)
          ! (len_trim and substrings: no temporary string per name and word)
          if (name(:len_trim(reserved(j))) == reserved(j)(:len_trim(reserved(j)))) then
            call raise(error, status_input, 'the contact name ''' // trim(name) // ''' starts with ''' // &
              trim(reserved(j)) // ''', as event kinds do (rest_, release_, stick, slip): choose another')
            return
          end if
        end do
        if (any(records%contact_name(:k - 1) == name)) then
          call raise(error, status_input, 'the contact name ''' // trim(name) // ''' is used twice ' // &
            '(walls are ''left'' and ''right'', the two-body link ''slot'', chain links ''link<i>'')')
          return
        end if
      end associate
    end do
  end subroutine check_names

  !> 'x<b> - x<a>' ('x<b> - n x<a>' with a gear ratio n; 'x<b>' against the ground,
  !> 'x<b> - w(0)' against a moving one: shifted), for messages (blank padded: callers trim).
  pure function difference_name(a, b, shifted, ratio) result(text)
    integer, intent(in) :: a, b
    logical, intent(in) :: shifted
    real(wp), intent(in) :: ratio      !< a gear ratio: 'x2 - 3.0 x1'
    character(len=3 * fmt_width + 16) :: text
    text = 'x' // trim(fmt(b))
    if (a > 0 .and. ratio /= 1.0_wp) then
      text = trim(text) // ' - ' // trim(fmt(ratio)) // ' x' // trim(fmt(a))
    else if (a > 0) then
      text = trim(text) // ' - x' // trim(fmt(a))
    end if
    if (shifted) text = trim(text) // ' - w(0)'
  end function difference_name

  !> The initial positions satisfy every contact's limits (within the rounding of the
  !> numbers the gap is made of, as for the tutorial's contacts), and every limit, width
  !> and initial gap is resolvable (impact1d_scene's resolvable, as the tutorial's are).
  subroutine check_start(input, records, error)
    type(scene_input), intent(in) :: input
    type(mechanism_records), intent(in) :: records
    type(error_type), allocatable, intent(inout) :: error
    real(wp) :: x(0:n_bodies_of(input)), d, limit, scale, gap, width
    integer :: k, side
    logical :: shifted
    ! (a message is made only for a contact that fails: a scene's set-up builds no strings)
    x(0) = 0.0_wp
    do k = 1, size(x) - 1
      x(k) = element_or(input, a_x, k, 0.0_wp)
    end do
    do k = 1, records%n_contacts
      associate (a => records%contact_body(1, k), b => records%contact_body(2, k))
        d = x(b) - records%contact_ratio(k) * x(a)
        shifted = .false.
        ! A moving ground end starts at w(0) = ground_amp sin(ground_phase) (+ table(0):
        ! checked once the tables are read, prepare_scene's second call).
        if (a == 0 .and. records%contact_moves(k)) then
          if (records%contact_ground(3, k) > 0.0_wp) then
            d = x(b) - records%contact_ground(2, k) * sin(records%contact_ground(4, k))
            shifted = .true.
          end if
          if (allocated(records%contact_table_path(k)%s)) then
            if (.not. records%tables_read) cycle
            d = d - table_value(records%contact_table(k), 0.0_wp)
            shifted = .true.
          end if
        end if
        do side = 1, 2
          if (.not. records%contact_has(side, k)) cycle
          limit = records%contact_limit(side, k)
          scale = max(abs(records%contact_ratio(k) * x(a)), abs(x(b)), abs(limit))
          gap = merge(d - limit, limit - d, side == 1)
          if (gap < -16.0_wp * eps_wp * scale) then
            call raise(error, status_input, 'the initial state violates the contact ''' // &
              trim(records%contact_name(k)) // ''': ' // trim(difference_name(a, b, shifted, &
              records%contact_ratio(k))) // ' = ' // trim(fmt(d)) // &
              ' is ' // trim(merge('below', 'above', side == 1)) // ' its ' // &
              trim(merge('lower', 'upper', side == 1)) // ' limit ' // trim(fmt(limit)))
            return
          end if
          ! (within the rounding of its numbers a gap is contact, as in validate_bodies)
          if (gap > 16.0_wp * eps_wp * scale .and. unresolved(gap, scale)) call resolvable('the initial gap ' // &
            'of the contact ''' // trim(records%contact_name(k)) // ''' (' // trim(difference_name(a, b, shifted, &
            records%contact_ratio(k))) // ')', &
            gap, scale, error)
          if (a > 0 .and. unresolved(limit, scale)) call resolvable('the contact ''' // &
            trim(records%contact_name(k)) // '''s ' // trim(merge('d_min', 'd_max', side == 1)), limit, scale, error)
        end do
        width = records%contact_limit(2, k) - records%contact_limit(1, k)
        if (all(records%contact_has(:, k)) .and. unresolved(width, scale)) call resolvable('the contact ''' // &
          trim(records%contact_name(k)) // '''s width d_max - d_min', width, scale, error)
        if (allocated(error)) return
      end associate
    end do
  end subroutine check_start

  !> The scene's contacts and springs as records (the chain shorthand expanded): the walls
  !> ('left' on body 1's position, 'right' on body N's), link i ('slot' with two bodies,
  !> 'link<i>' beyond) on x(i+1) - x(i) with the bodies' meeting (d_min = 0, restitution
  !> r_meet, default 1) unless the link gives its own d_min or a &contact joins the pair,
  !> then the &contact records in file order (unnamed: 'contact<j>'); springs to the ground
  !> (k, x_rest, c: k1 k2), between neighbours (k_link, d_rest, c_link: k12), then the
  !> &spring records in file order. A record written with b = 0 is turned round (a = 0).
  subroutine input_records(input, records)
    type(scene_input), intent(in) :: input
    type(mechanism_records), intent(out) :: records
    integer :: n, nc, ne
    n = n_bodies_of(input)
    nc = 2 + (n - 1)
    ne = n + (n - 1)
    if (allocated(input%chain%contacts)) nc = nc + size(input%chain%contacts)
    if (allocated(input%chain%springs)) ne = ne + size(input%chain%springs)
    allocate(records%contact_body(2, nc), records%contact_has(2, nc), records%contact_limit(2, nc), &
      records%contact_restitution(2, nc), records%contact_name(nc), records%contact_k(nc), records%contact_c(nc))
    allocate(records%element_body(2, ne), records%element_k(ne), records%element_c(ne), records%element_rest(ne))
    allocate(records%contact_ground(n_ground_fields, nc), records%element_ground(n_ground_fields, ne), &
      records%contact_moves(nc), records%element_moves(ne), records%contact_ratio(nc), records%element_ratio(ne))
    records%contact_ratio = 1.0_wp
    records%element_ratio = 1.0_wp
    records%contact_ground = 0.0_wp
    records%element_ground = 0.0_wp
    records%contact_moves = .false.
    records%element_moves = .false.
    allocate(records%contact_table_path(nc), records%element_table_path(ne))
    records%contact_has = .false.
    records%contact_limit = 0.0_wp
    records%contact_restitution = 1.0_wp
    records%contact_k = 0.0_wp
    records%contact_c = 0.0_wp
    call wall_records(input, n, records)
    call link_records(input, n, records)
    call contact_records(input, records)
    call element_records(input, n, records)
    call shrink(records)
    call sine_records(input, records)
    call friction_records(input, records)
  end subroutine input_records

  !> The &friction records in file order (mus = mu when not given; named 'friction<r>' when
  !> not named).
  pure subroutine friction_records(input, records)
    type(scene_input), intent(in) :: input
    type(mechanism_records), intent(inout) :: records
    integer :: r, nf
    nf = 0
    if (allocated(input%chain%frictions)) nf = size(input%chain%frictions)
    records%n_frictions = nf
    allocate(records%friction_body(2, nf), records%friction_slide(nf), records%friction_static(nf), &
      records%friction_name(nf))
    do r = 1, nf
      associate (rec => input%chain%frictions(r))
        records%friction_body(:, r) = nint(rec%value(1:2))
        records%friction_slide(r) = rec%value(r_mu) * rec%value(r_normal)
        records%friction_static(r) = merge(rec%value(r_mus), rec%value(r_mu), rec%given(r_mus)) * rec%value(r_normal)
        records%friction_name(r) = 'friction' // trim(fmt(r))
        if (allocated(rec%name)) then
          if (len_trim(rec%name) > 0) records%friction_name(r) = rec%name
        end if
      end associate
    end do
  end subroutine friction_records

  !> The &sine records in file order (phase 0 when not given).
  pure subroutine sine_records(input, records)
    type(scene_input), intent(in) :: input
    type(mechanism_records), intent(inout) :: records
    integer :: r
    records%n_sines = 0
    if (allocated(input%chain%sines)) records%n_sines = size(input%chain%sines)
    allocate(records%sine_body(records%n_sines), records%sine_amp(records%n_sines), &
      records%sine_period(records%n_sines), records%sine_phase(records%n_sines))
    do r = 1, records%n_sines
      associate (rec => input%chain%sines(r))
        records%sine_body(r) = nint(rec%value(r_body))
        records%sine_amp(r) = rec%value(r_amp)
        records%sine_period(r) = rec%value(r_period)
        records%sine_phase(r) = merge(rec%value(r_phase), 0.0_wp, rec%given(r_phase))
      end associate
    end do
  end subroutine sine_records

  !> 'left' (0, 1) with lower limit x_left; 'right' (0, N) with upper limit x_right.
  subroutine wall_records(input, n, records)
    type(scene_input), intent(in) :: input
    integer, intent(in) :: n
    type(mechanism_records), intent(inout) :: records
    if (input%given(i_x_left)) then
      call add_contact(records, 'left', 0, 1, 1, input%value(i_x_left), value_or(input, i_r_left, 1.0_wp))
      call wall_motion(i_x_left_v, i_x_left_table)
    end if
    if (input%given(i_x_right)) then
      call add_contact(records, 'right', 0, n, 2, input%value(i_x_right), value_or(input, i_r_right, 1.0_wp))
      call wall_motion(i_x_right_v, i_x_right_table)
    end if

  contains

    !> The wall just added moves as its fields from first (x_left_v ...) and its table (text
    !> field table: x_left_table ...) say, when any is given.
    subroutine wall_motion(first, table)
      integer, intent(in) :: first, table
      associate (k => records%n_contacts, given => input%given(first:first + n_ground_fields - 1))
        records%contact_moves(k) = any(given)
        records%contact_ground(:, k) = merge(input%value(first:first + n_ground_fields - 1), 0.0_wp, given)
        if (given_slot(input, n_real + table)) call set_table_path(records%contact_table_path(k), &
          records%contact_moves(k), trim(input%text(table)%s))
      end associate
    end subroutine wall_motion
  end subroutine wall_records

  !> Link i between bodies i and i+1, as its &link elements and the meeting make it.
  subroutine link_records(input, n, records)
    type(scene_input), intent(in) :: input
    integer, intent(in) :: n
    type(mechanism_records), intent(inout) :: records
    character(len=name_len) :: name
    integer :: i, first
    do i = 1, n - 1
      name = 'slot'
      if (n > tutorial_bodies) write(name, '("link", i0)') i
      first = records%n_contacts + 1
      if (has_element(input, a_d_min, i)) then
        call add_contact(records, name, i, i + 1, 1, element_or(input, a_d_min, i, 0.0_wp), &
          element_or(input, a_r_min, i, 1.0_wp))
      else if (.not. contact_joins(input, i, i + 1)) then
        call add_contact(records, name, i, i + 1, 1, 0.0_wp, &
          element_or(input, a_r_min, i, merge(input%chain%r_meet, 1.0_wp, input%chain%has_r_meet)))
      end if
      if (has_element(input, a_d_max, i)) then
        if (records%n_contacts < first) call add_contact(records, name, i, i + 1, 2, 0.0_wp, 1.0_wp)
        records%contact_has(2, first) = .true.
        records%contact_limit(2, first) = element_or(input, a_d_max, i, 0.0_wp)
        records%contact_restitution(2, first) = element_or(input, a_r_max, i, 1.0_wp)
      end if
    end do
  end subroutine link_records

  !> Whether a &contact record joins bodies i and j (either way round).
  pure logical function contact_joins(input, i, j)
    type(scene_input), intent(in) :: input
    integer, intent(in) :: i, j
    integer :: r
    contact_joins = .false.
    if (.not. allocated(input%chain%contacts)) return
    do r = 1, size(input%chain%contacts)
      associate (ends => nint(input%chain%contacts(r)%value([r_a, r_b])))
        contact_joins = contact_joins .or. (minval(ends) == i .and. maxval(ends) == j)
      end associate
    end do
  end function contact_joins

  !> The &contact records in file order, a record with b = 0 turned round: on x_a - x_b
  !> = -(x_b - x_a), so its limits negate and swap.
  subroutine contact_records(input, records)
    type(scene_input), intent(in) :: input
    type(mechanism_records), intent(inout) :: records
    character(len=name_len) :: name
    integer :: r, k, ends(2)
    if (.not. allocated(input%chain%contacts)) return
    do r = 1, size(input%chain%contacts)
      associate (rec => input%chain%contacts(r))
        write(name, '("contact", i0)') r
        if (allocated(rec%name)) then
          if (len_trim(rec%name) > 0) name = rec%name
        end if
        ends = nint(rec%value([r_a, r_b]))
        k = records%n_contacts + 1
        call add_contact(records, name, ends(1), ends(2), 1, rec%value(r_d_min), 1.0_wp)
        records%contact_has(:, k) = rec%given([r_d_min, r_d_max])
        records%contact_limit(:, k) = merge(rec%value([r_d_min, r_d_max]), 0.0_wp, rec%given([r_d_min, r_d_max]))
        records%contact_restitution(:, k) = merge(rec%value([r_r_min, r_r_max]), 1.0_wp, rec%given([r_r_min, r_r_max]))
        if (rec%given(r_stop_k)) records%contact_k(k) = rec%value(r_stop_k)
        if (rec%given(r_stop_c)) records%contact_c(k) = rec%value(r_stop_c)
        records%contact_ground(:, k) = ground_of(rec, r_ground_v)
        records%contact_moves(k) = any(rec%given(r_ground_v:r_ground_v + n_ground_fields - 1))
        if (rec%given(r_ratio)) records%contact_ratio(k) = rec%value(r_ratio)
        if (rec%given(r_ground_table)) call set_table_path(records%contact_table_path(k), records%contact_moves(k), &
          rec%table)
        if (ends(2) == 0) then
          records%contact_body(:, k) = [0, ends(1)]
          records%contact_has(:, k) = records%contact_has([2, 1], k)
          records%contact_limit(:, k) = -records%contact_limit([2, 1], k) + 0.0_wp
          records%contact_restitution(:, k) = records%contact_restitution([2, 1], k)
        end if
      end associate
    end do
  end subroutine contact_records

  !> One more contact on x_b - x_a with one limit (side 1 lower, 2 upper).
  pure subroutine add_contact(records, name, a, b, side, limit, restitution)
    type(mechanism_records), intent(inout) :: records
    character(len=*), intent(in) :: name
    integer, intent(in) :: a, b, side
    real(wp), intent(in) :: limit, restitution
    integer :: k
    records%n_contacts = records%n_contacts + 1
    k = records%n_contacts
    records%contact_name(k) = name
    records%contact_body(:, k) = [a, b]
    records%contact_has(side, k) = .true.
    records%contact_limit(side, k) = limit
    records%contact_restitution(side, k) = restitution
  end subroutine add_contact

  !> Springs and dampers: to the ground (body arrays k, x_rest, c), between neighbours
  !> (k_link, d_rest, c_link), then the &spring records (b = 0 turned round: rest negates).
  subroutine element_records(input, n, records)
    type(scene_input), intent(in) :: input
    integer, intent(in) :: n
    type(mechanism_records), intent(inout) :: records
    integer :: i, r, ends(2)
    do i = 1, n
      if (has_element(input, a_k, i) .or. has_element(input, a_c, i)) call add_element(records, 0, i, &
        element_or(input, a_k, i, 0.0_wp), element_or(input, a_x_rest, i, 0.0_wp), element_or(input, a_c, i, 0.0_wp))
    end do
    do i = 1, n - 1
      if (has_element(input, a_k_link, i) .or. has_element(input, a_c_link, i)) call add_element(records, i, &
        i + 1, element_or(input, a_k_link, i, 0.0_wp), element_or(input, a_d_rest, i, 0.0_wp), &
        element_or(input, a_c_link, i, 0.0_wp))
    end do
    if (.not. allocated(input%chain%springs)) return
    do r = 1, size(input%chain%springs)
      associate (rec => input%chain%springs(r))
        ends = nint(rec%value([r_a, r_b]))
        if (ends(2) == 0) then
          call add_element(records, 0, ends(1), rec%value(r_k), -rec%value(r_d_rest) + 0.0_wp, rec%value(r_c))
        else
          call add_element(records, ends(1), ends(2), rec%value(r_k), rec%value(r_d_rest), rec%value(r_c))
        end if
        records%element_ground(:, records%n_elements) = ground_of(rec, r_spring_ground_v)
        records%element_moves(records%n_elements) = any(rec%given(r_spring_ground_v:r_spring_ground_v + &
          n_ground_fields - 1))
        if (rec%given(r_spring_ratio)) records%element_ratio(records%n_elements) = rec%value(r_spring_ratio)
        if (rec%given(r_spring_ground_table)) call set_table_path(records%element_table_path(records%n_elements), &
          records%element_moves(records%n_elements), rec%table)
      end associate
    end do
  end subroutine element_records

  !> A record's ground end moved by the table at path (ground_table).
  pure subroutine set_table_path(item, moves, path)
    type(text_item), intent(inout) :: item
    logical, intent(inout) :: moves
    character(len=*), intent(in) :: path
    item%s = path
    moves = .true.
  end subroutine set_table_path

  !> One more element between a and b.
  pure subroutine add_element(records, a, b, k, rest, c)
    type(mechanism_records), intent(inout) :: records
    integer, intent(in) :: a, b
    real(wp), intent(in) :: k, rest, c
    records%n_elements = records%n_elements + 1
    associate (e => records%n_elements)
      records%element_body(:, e) = [a, b]
      records%element_k(e) = k
      records%element_rest(e) = rest
      records%element_c(e) = c
    end associate
  end subroutine add_element

  !> The arrays cut to the records made.
  pure subroutine shrink(records)
    type(mechanism_records), intent(inout) :: records
    associate (nc => records%n_contacts, ne => records%n_elements)
      records%contact_body = records%contact_body(:, :nc)
      records%contact_has = records%contact_has(:, :nc)
      records%contact_limit = records%contact_limit(:, :nc)
      records%contact_restitution = records%contact_restitution(:, :nc)
      records%contact_name = records%contact_name(:nc)
      records%contact_k = records%contact_k(:nc)
      records%contact_c = records%contact_c(:nc)
      records%contact_ground = records%contact_ground(:, :nc)
      records%element_ground = records%element_ground(:, :ne)
      records%contact_moves = records%contact_moves(:nc)
      records%element_moves = records%element_moves(:ne)
      records%contact_ratio = records%contact_ratio(:nc)
      records%element_ratio = records%element_ratio(:ne)
      records%contact_table_path = records%contact_table_path(:nc)
      records%element_table_path = records%element_table_path(:ne)
      records%element_body = records%element_body(:, :ne)
      records%element_k = records%element_k(:ne)
      records%element_c = records%element_c(:ne)
      records%element_rest = records%element_rest(:ne)
    end associate
  end subroutine shrink

  !> Name of input field id (the flat API's numbering: the tutorial's scalars, its texts,
  !> the arrays, r_meet, the &contact and &spring record fields as 'contact.a').
  pure function field_name(id) result(name)
    integer, intent(in) :: id
    character(len=24) :: name     ! blank padded: callers trim
    name = ''
    if (id >= 1 .and. id <= n_real) then
      name = real_names(id)
    else if (id > n_real .and. id <= id_arrays) then
      name = text_names(id - n_real)
    else if (id > id_arrays .and. id < id_r_meet) then
      name = array_names(id - id_arrays)
    else if (id == id_r_meet) then
      name = 'r_meet'
    else if (id > id_contact .and. id <= id_spring) then
      name = 'contact.' // contact_fields(id - id_contact)
    else if (id > id_spring .and. id <= id_sine) then
      name = 'spring.' // spring_fields(id - id_spring)
    else if (id > id_sine .and. id <= id_friction) then
      name = 'sine.' // sine_fields(id - id_sine)
    else if (id > id_friction .and. id < id_bodies_out) then
      name = 'friction.' // friction_fields(id - id_friction)
    else if (id == id_bodies_out) then
      name = 'bodies_out'
    end if
  end function field_name

  !> Whether field id holds text (a text scalar, f_table's elements, a contact's name).
  pure logical function field_is_text(id)
    integer, intent(in) :: id
    field_is_text = (id > n_real .and. id <= id_arrays) .or. id == id_arrays + a_f_table .or. &
      id == id_contact + r_name .or. id == id_friction + r_friction_name .or. id == id_contact + r_ground_table .or. &
      id == id_spring + r_spring_ground_table
  end function field_is_text

  !> Field id := value: a scalar (index ignored), element index of an array, or the field
  !> of record index. An array or the records grow to index (elements skipped are NaN, which
  !> the checks refuse).
  pure subroutine assign_number(input, id, index, value)
    type(scene_input), intent(inout) :: input
    integer, intent(in) :: id, index
    real(wp), intent(in) :: value
    if (id >= 1 .and. id <= n_real) then
      input%value(id) = value
      input%given(id) = .true.
    else if (id > id_arrays .and. id < id_r_meet) then
      call grow_array(input%chain%array(id - id_arrays), index)
      input%chain%array(id - id_arrays)%v(index) = value
    else if (id == id_r_meet) then
      input%chain%r_meet = value
      input%chain%has_r_meet = .true.
    else if (id > id_contact .and. id <= id_spring) then
      call set_record_field(input%chain%contacts, index, id - id_contact, value)
    else if (id > id_spring .and. id <= id_sine) then
      call set_record_field(input%chain%springs, index, id - id_spring, value)
    else if (id > id_sine .and. id <= id_friction) then
      call set_record_field(input%chain%sines, index, id - id_sine, value)
    else if (id > id_friction .and. id < id_bodies_out) then
      call set_record_field(input%chain%frictions, index, id - id_friction, value)
    else if (id == id_bodies_out) then
      call set_body_out(input, index, value)
    end if
  end subroutine assign_number

  !> Element index of bodies_out := value (grown to index, bodies skipped 0; a value that is
  !> not a whole number is -1: check_bodies_out refuses either as a body the scene lacks).
  pure subroutine set_body_out(input, index, value)
    type(scene_input), intent(inout) :: input
    integer, intent(in) :: index
    real(wp), intent(in) :: value
    integer, allocatable :: bodies(:)
    if (.not. allocated(input%bodies_out)) allocate(input%bodies_out(0))
    if (size(input%bodies_out) < index) then
      allocate(bodies(index))
      bodies = 0
      bodies(:size(input%bodies_out)) = input%bodies_out
      call move_alloc(bodies, input%bodies_out)
    end if
    input%bodies_out(index) = -1
    if (abs(value) < 1.0e9_wp) then
      if (value == aint(value)) input%bodies_out(index) = nint(value)
    end if
  end subroutine set_body_out

  !> Field f of record index := value (the records grown to index).
  pure subroutine set_record_field(records, index, f, value)
    type(record_input), allocatable, intent(inout) :: records(:)
    integer, intent(in) :: index, f
    real(wp), intent(in) :: value
    call grow_records(records, index)
    records(index)%value(f) = value
    records(index)%given(f) = .true.
  end subroutine set_record_field

  !> Text field id := text (a text scalar, element index of f_table, record index's name).
  pure subroutine assign_text(input, id, index, text)
    type(scene_input), intent(inout) :: input
    integer, intent(in) :: id, index
    character(len=*), intent(in) :: text
    if (id > n_real .and. id <= id_arrays) then
      call set_text(input, id - n_real, text)
    else if (id == id_arrays + a_f_table) then
      call grow_array(input%chain%array(a_f_table), index)
      input%chain%array(a_f_table)%t(index)%s = text
    else if (id == id_contact + r_name) then
      call set_record_text(input%chain%contacts, index, r_name, text, .false.)
    else if (id == id_friction + r_friction_name) then
      call set_record_text(input%chain%frictions, index, r_friction_name, text, .false.)
    else if (id == id_contact + r_ground_table) then
      call set_record_text(input%chain%contacts, index, r_ground_table, text, .true.)
    else if (id == id_spring + r_spring_ground_table) then
      call set_record_text(input%chain%springs, index, r_spring_ground_table, text, .true.)
    end if
  end subroutine assign_text

  !> Record index's text field f := text: its name, or its ground_table's path (table).
  pure subroutine set_record_text(records, index, f, text, table)
    type(record_input), allocatable, intent(inout) :: records(:)
    integer, intent(in) :: index, f
    character(len=*), intent(in) :: text
    logical, intent(in) :: table
    call grow_records(records, index)
    if (table) then
      records(index)%table = text
    else
      records(index)%name = text
    end if
    records(index)%given(f) = .true.
  end subroutine set_record_text

  !> An array holds at least n elements (new numbers NaN, new texts '').
  pure subroutine grow_array(array, n)
    type(written_array), intent(inout) :: array
    integer, intent(in) :: n
    real(wp), allocatable :: v(:)
    type(text_item), allocatable :: t(:)
    integer :: k, room
    if (array%n >= n) return
    room = 0
    if (allocated(array%v) .and. allocated(array%t)) room = min(size(array%v), size(array%t))
    if (room < n) then
      ! Room doubles: an array assigned element by element (Python's N-body scenes, 6 arrays
      ! of N) was copied whole at each element, O(N^2): 1.8 s for 3400 bodies.
      room = max(n, 2 * room)
      allocate(v(room), t(room))
      v = ieee_value(1.0_wp, ieee_quiet_nan)
      do k = 1, room
        t(k)%s = ''
      end do
      if (allocated(array%v)) v(:array%n) = array%v(:array%n)
      if (allocated(array%t)) t(:array%n) = array%t(:array%n)
      call move_alloc(v, array%v)
      call move_alloc(t, array%t)
    end if
    array%n = n
  end subroutine grow_array

  !> At least n records.
  pure subroutine grow_records(records, n)
    type(record_input), allocatable, intent(inout) :: records(:)
    integer, intent(in) :: n
    type(record_input), allocatable :: more(:)
    if (.not. allocated(records)) allocate(records(0))
    if (size(records) >= n) return
    allocate(more(n - size(records)))
    records = [records, more]
  end subroutine grow_records

  !> The scene as assignments (what the flat API's read_scene returns): every scalar given
  !> (index 0), every array element, r_meet, every record field given (index: the record);
  !> texts likewise, non-empty ones only. n_numbers and n_texts count them all, whatever
  !> the room (field(:), texts(:) are filled as far as they go).
  subroutine scene_assignments(input, field, index, value, n_numbers, text_field, text_index, texts, n_texts)
    type(scene_input), intent(in) :: input
    integer, intent(out) :: field(:), index(:), text_field(:), text_index(:)
    real(wp), intent(out) :: value(:)
    type(text_item), intent(out) :: texts(:)
    integer, intent(out) :: n_numbers, n_texts
    integer :: id, i, last
    n_numbers = 0
    n_texts = 0
    do id = 1, n_ids
      last = 0
      if (id > id_arrays .and. id < id_r_meet) last = input%chain%array(id - id_arrays)%n
      if (id > id_contact .and. id <= id_spring .and. allocated(input%chain%contacts)) last = size(input%chain%contacts)
      if (id > id_spring .and. id <= id_sine .and. allocated(input%chain%springs)) last = size(input%chain%springs)
      if (id > id_sine .and. id <= id_friction .and. allocated(input%chain%sines)) last = size(input%chain%sines)
      if (id > id_friction .and. id < id_bodies_out .and. allocated(input%chain%frictions)) &
        last = size(input%chain%frictions)
      if (id == id_bodies_out .and. allocated(input%bodies_out)) last = size(input%bodies_out)
      if (id <= id_arrays .or. id == id_r_meet) then
        call put_field(input, id, 0, field, index, value, n_numbers, text_field, text_index, texts, n_texts)
      end if
      do i = 1, last
        call put_field(input, id, i, field, index, value, n_numbers, text_field, text_index, texts, n_texts)
      end do
    end do
  end subroutine scene_assignments

  !> Field id at index i, if given, as the next number or text.
  subroutine put_field(input, id, i, field, index, value, n_numbers, text_field, text_index, texts, n_texts)
    type(scene_input), intent(in) :: input
    integer, intent(in) :: id, i
    integer, intent(inout) :: field(:), index(:), text_field(:), text_index(:), n_numbers, n_texts
    real(wp), intent(inout) :: value(:)
    type(text_item), intent(inout) :: texts(:)
    character(len=:), allocatable :: text
    real(wp) :: number
    logical :: given
    call field_value(input, id, i, given, number, text)
    if (.not. given) return
    if (field_is_text(id)) then
      n_texts = n_texts + 1
      if (n_texts > size(texts)) return
      text_field(n_texts) = id
      text_index(n_texts) = i
      texts(n_texts)%s = text
    else
      n_numbers = n_numbers + 1
      if (n_numbers > size(value)) return
      field(n_numbers) = id
      index(n_numbers) = i
      value(n_numbers) = number
    end if
  end subroutine put_field

  !> Field id at index i as the input holds it (given false: absent or an empty text).
  subroutine field_value(input, id, i, given, number, text)
    type(scene_input), intent(in) :: input
    integer, intent(in) :: id, i
    logical, intent(out) :: given
    real(wp), intent(out) :: number
    character(len=:), allocatable, intent(out) :: text
    number = 0.0_wp
    text = ''
    given = .false.
    if (id <= n_real) then
      given = input%given(id)
      number = input%value(id)
    else if (id <= id_arrays) then
      text = input%text(id - n_real)%s
    else if (id == id_arrays + a_f_table) then
      text = input%chain%array(a_f_table)%t(i)%s
      given = .true.
    else if (id < id_r_meet) then
      number = input%chain%array(id - id_arrays)%v(i)
      given = .true.
    else if (id == id_r_meet) then
      given = input%chain%has_r_meet
      number = input%chain%r_meet
    else if (id <= id_spring) then
      call record_value(input%chain%contacts(i), id - id_contact, r_name, given, number, text, r_ground_table)
    else if (id <= id_sine) then
      call record_value(input%chain%springs(i), id - id_spring, 0, given, number, text, r_spring_ground_table)
    else if (id <= id_friction) then
      call record_value(input%chain%sines(i), id - id_sine, 0, given, number, text)
    else if (id < id_bodies_out) then
      call record_value(input%chain%frictions(i), id - id_friction, r_friction_name, given, number, text)
    else
      number = real(input%bodies_out(i), wp)
      given = .true.
    end if
    if (field_is_text(id) .and. id /= id_arrays + a_f_table) given = len(text) > 0
  end subroutine field_value

  !> Field f of a record whose name is field name_field (0: it has none), whose ground_table
  !> is field table_field (absent: it has none).
  subroutine record_value(rec, f, name_field, given, number, text, table_field)
    type(record_input), intent(in) :: rec
    integer, intent(in) :: f, name_field
    logical, intent(out) :: given
    real(wp), intent(out) :: number
    character(len=:), allocatable, intent(inout) :: text
    integer, intent(in), optional :: table_field
    given = rec%given(f)
    number = rec%value(f)
    if (allocated(rec%name) .and. f == name_field) text = rec%name
    if (present(table_field)) then
      if (allocated(rec%table) .and. f == table_field) text = rec%table
    end if
  end subroutine record_value
end module impact1d_chain

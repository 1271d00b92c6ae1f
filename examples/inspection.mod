MODULE Inspection
    ! Camera inspection on the IRB 120 (joulepath example). The camera passes over eight
    ! views of a part at speed (fly-by z50, the pictures are triggered on the fly) and
    ! returns to its park position.
    PERS tooldata tCamera := [TRUE, [[0, 0, 120], [1, 0, 0, 0]], [0.4, [0, 0, 60], [1, 0, 0, 0], 0, 0, 0]];
    CONST jointtarget jPark := [[30, 0, 0, 0, 30, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
    CONST robtarget pView1 := [[460, 150, 350], [0, 0, 1, 0], [0, 0, 0, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
    CONST robtarget pView2 := [[437, 207, 350], [0, 0, 1, 0], [0, 0, 0, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
    CONST robtarget pView3 := [[380, 230, 350], [0, 0, 1, 0], [0, 0, 0, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
    CONST robtarget pView4 := [[323, 207, 350], [0, 0, 1, 0], [0, 0, 0, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
    CONST robtarget pView5 := [[300, 150, 350], [0, 0, 1, 0], [0, 0, 0, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
    CONST robtarget pView6 := [[323, 93, 350], [0, 0, 1, 0], [0, 0, 0, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
    CONST robtarget pView7 := [[380, 70, 350], [0, 0, 1, 0], [0, 0, 0, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
    CONST robtarget pView8 := [[437, 93, 350], [0, 0, 1, 0], [0, 0, 0, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];

    PROC main()
        MoveAbsJ jPark, v1000, fine, tCamera;
        WHILE TRUE DO
            MoveJ pView1, v2000, z50, tCamera;
            MoveJ pView2, v2000, z50, tCamera;
            MoveJ pView3, v2000, z50, tCamera;
            MoveJ pView4, v2000, z50, tCamera;
            MoveJ pView5, v2000, z50, tCamera;
            MoveJ pView6, v2000, z50, tCamera;
            MoveJ pView7, v2000, z50, tCamera;
            MoveJ pView8, v2000, z50, tCamera;
            MoveAbsJ jPark, v2000, fine, tCamera;
            ! joulepath: idle
            WaitTime 1.5;
        ENDWHILE
    ENDPROC
ENDMODULE
